//! Unit tests of the prediction path against candle and finite differences, the model file and a
//! tiny training run.

use std::path::PathBuf;

use super::*;
use crate::Error;
use crate::space::ParameterSpace;

pub(super) fn space() -> ParameterSpace {
    let mut text = String::from("name = \"test\"\n");
    for (k, (lo, hi)) in [(0.2, 5.0), (0.02, 1.0), (-1.0, 1.0)].iter().enumerate() {
        text += &format!(
            "[[dimensions]]\nname = \"p{k}\"\nunit = \"1\"\nrange = [{lo}, {hi}]\ntarget = \"parameter:p{k}\"\n"
        );
    }
    text +=
        "[[dimensions]]\nname = \"U_B\"\nunit = \"V\"\nrange = [10.0, 3000.0]\ntarget = \"bias\"\n";
    ParameterSpace::from_toml_str(&text, &PathBuf::from("test.toml")).unwrap()
}

/// A synthetic C-V-like function of (p, U): falls with U, saturates at a p-dependent voltage.
fn synthetic_c12(x: &[f64]) -> f64 {
    let ud = 500.0 + 600.0 * x[0] + 400.0 * x[1];
    let u = x[3].min(ud);
    40.0 * (1.0 + 0.3 * x[2]) * (1.0 + 3.0 * ((ud - u) / ud).powi(2)) + 5.0 * x[1]
}

fn write_set(path: &std::path::Path, sp: &ParameterSpace, n: usize, offset: usize) {
    let g = |i: usize, k: usize| {
        ((i as f64 + 0.5) * [0.7548776662, 0.5698402910, 0.4301597090, 0.3247179572][k]).fract()
    };
    let mut text =
        String::from("index,u_p0,u_p1,u_p2,u_U_B,p0,p1,p2,U_B,c12_pF,status,c12_err_pF,seconds\n");
    for i in offset..offset + n {
        let u: Vec<f64> = (0..4).map(|k| g(i, k)).collect();
        let x = sp.from_unit(&u);
        let row: Vec<String> = u.iter().chain(&x).map(|v| v.to_string()).collect();
        text += &format!("{i},{},{},ok,0.001,0.1\n", row.join(","), synthetic_c12(&x));
    }
    std::fs::write(path, text).unwrap();
}

/// The bias map of [`space`]'s U_B (10-3000 V, uniform).
pub(super) fn test_bias() -> BiasMap {
    BiasMap {
        lo_v: 10.0,
        hi_v: 3000.0,
        log_uniform: false,
    }
}

pub(super) fn random_network(arch: &Architecture, seed: u64) -> Network {
    let mut net = initial_network(arch, 3, Some(test_bias()), seed).unwrap();
    // Non-zero biases so that every code path matters.
    for (k, l) in net.trunk.iter_mut().chain(net.head.iter_mut()).enumerate() {
        for (i, b) in l.b.iter_mut().enumerate() {
            *b = 0.1 * ((k * 31 + i * 7) as f64).sin();
        }
    }
    net
}

#[test]
fn jacobian_matches_central_differences() {
    for arch in [
        Architecture {
            trunk: vec![],
            head: vec![12, 12],
            steps: None,
            gate: false,
        },
        Architecture {
            trunk: vec![10, 8],
            head: vec![6, 5],
            steps: None,
            gate: false,
        },
        Architecture {
            trunk: vec![10, 8],
            head: vec![6],
            steps: Some(5),
            gate: false,
        },
        Architecture {
            trunk: vec![10, 8],
            head: vec![6],
            steps: Some(5),
            gate: true,
        },
    ] {
        let net = random_network(&arch, 3);
        let zp = [0.3, -1.1, 0.7];
        let zu = [-1.5, 0.0, 0.4, 2.0];
        let mut y = [0.0; 4];
        let mut jac = [0.0; 12];
        net.curve_jacobian(&zp, &zu, &mut y, &mut jac);
        let mut y0 = [0.0; 4];
        net.curve(&zp, &zu, &mut y0);
        assert_eq!(y, y0, "the Jacobian pass gives the same values");
        for j in 0..3 {
            let h = 1e-6;
            let (mut a, mut b) = (zp, zp);
            a[j] += h;
            b[j] -= h;
            let (mut ya, mut yb) = ([0.0; 4], [0.0; 4]);
            net.curve(&a, &zu, &mut ya);
            net.curve(&b, &zu, &mut yb);
            for k in 0..4 {
                let fd = (ya[k] - yb[k]) / (2.0 * h);
                assert!(
                    (fd - jac[k * 3 + j]).abs() < 1e-7 * (1.0 + fd.abs()),
                    "{arch:?} k {k} j {j}: {fd} vs {}",
                    jac[k * 3 + j]
                );
            }
        }
    }
}

#[test]
fn plain_path_matches_candle() {
    for (steps, gate) in [(None, false), (Some(6), false), (Some(6), true)] {
        let arch = Architecture {
            trunk: vec![16, 16],
            head: vec![16, 8],
            steps,
            gate,
        };
        let net = random_network(&arch, 5);
        let units: Vec<f64> = (0..40)
            .map(|i| ((i as f64 + 0.5) * 0.618_033_988_7).fract())
            .collect();
        let c = candle_outputs(&net, &units, 4).unwrap();
        for (i, row) in units.chunks(4).enumerate() {
            let z: Vec<f64> = row.iter().map(|&u| unit_to_z(u)).collect();
            let mut y = [0.0];
            net.curve(&z[..3], &z[3..], &mut y);
            assert!(
                (y[0] - c[i]).abs() < 2e-5 * (1.0 + y[0].abs()),
                "{steps:?} row {i}: {} vs {}",
                y[0],
                c[i]
            );
        }
    }
}

#[test]
fn the_steps_bias_map_is_the_log_bias_range() {
    let m = test_bias();
    assert_eq!(m.t_of_unit(0.0), 0.0);
    assert!((m.t_of_unit(1.0) - 1.0).abs() < 1e-15);
    // U = 100 V: u = 90/2990, t = ln(10)/ln(300).
    let t = m.t_of_unit(90.0 / 2990.0);
    assert!((t - 10f64.ln() / 300f64.ln()).abs() < 1e-14, "{t}");
    for u in [1e-3, 0.2, 0.5, 0.97] {
        assert!((m.t_of_z(unit_to_z(u)) - m.t_of_unit(u)).abs() < 1e-12);
    }
    let log = BiasMap {
        log_uniform: true,
        ..m
    };
    assert_eq!(log.t_of_unit(0.3), 0.3);
    let mut sp = space();
    sp.dimensions[3].range = [0.0, 3000.0];
    let e = BiasMap::of(&sp.dimensions[3]).unwrap_err().to_string();
    assert!(e.contains("U_B") && e.contains("positive"), "{e}");
}

#[test]
fn a_steps_network_falls_with_the_bias_everywhere() {
    let zu: Vec<f64> = (1..400).map(|k| unit_to_z(k as f64 / 400.0)).collect();
    let mut y = vec![0.0; zu.len()];
    for (seed, gate) in (0..20).flat_map(|s| [(s, false), (s, true)]) {
        let arch = Architecture {
            trunk: vec![12],
            head: vec![12],
            steps: Some(8),
            gate,
        };
        let mut net = random_network(&arch, seed);
        // Large outputs too: narrow, far-moved, tall steps.
        for (i, b) in net.out.b.iter_mut().enumerate() {
            *b = 3.0 * ((seed as usize * 13 + i * 5) as f64).sin();
        }
        for zp in [[0.0, 0.0, 0.0], [2.5, -1.0, 0.3], [-3.0, 3.0, -2.0]] {
            net.curve(&zp, &zu, &mut y);
            for k in 1..y.len() {
                assert!(
                    y[k] <= y[k - 1],
                    "seed {seed} gate {gate} {zp:?} k {k}: {} > {}",
                    y[k],
                    y[k - 1]
                );
            }
        }
    }
}

/// A fresh folder with 600 training and 150 test rows of [`synthetic_c12`]: (folder, space,
/// training file, test file, both sets as read).
pub(super) fn synthetic_sets(
    name: &str,
) -> (PathBuf, ParameterSpace, PathBuf, PathBuf, DataSet, DataSet) {
    let dir = std::env::temp_dir().join(format!("hpge-surrogate-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sp = space();
    let (tr, te) = (dir.join("train.csv"), dir.join("test.csv"));
    write_set(&tr, &sp, 600, 0);
    write_set(&te, &sp, 150, 1000);
    let train_set = DataSet::read(&tr, &sp).unwrap();
    let test_set = DataSet::read(&te, &sp).unwrap();
    (dir, sp, tr, te, train_set, test_set)
}

#[test]
fn tiny_training_lowers_the_loss_and_the_file_reloads_identically() {
    let (dir, sp, tr, _, train_set, test_set) = synthetic_sets("unit");
    let recipe = Recipe::named("tiny").unwrap();
    let mut epochs = 0;
    let t = train(&recipe, &train_set, &test_set, 11, &mut |_| epochs += 1).unwrap();
    assert_eq!(epochs, recipe.total_epochs());
    let first = t.curves.first().unwrap();
    let last = t.curves.last().unwrap();
    assert!(
        last.train_loss < 0.5 * first.train_loss,
        "{} -> {}",
        first.train_loss,
        last.train_loss
    );
    assert!(last.test_loss < 0.5 * first.test_loss);
    // Same seed, same network.
    let again = train(&recipe, &train_set, &test_set, 11, &mut |_| {}).unwrap();
    assert_eq!(again.members, t.members);

    let info = ModelInfo {
        format: FORMAT.into(),
        format_version: FORMAT_VERSION,
        program_version: "test".into(),
        space: sp.clone(),
        inputs: vec!["p0".into(), "p1".into(), "p2".into(), "U_B".into()],
        input_map: "z = Phi^-1(u)".into(),
        output: t.output,
        recipe_name: "tiny".into(),
        recipe: Some(recipe),
        seed: 11,
        training: DataInfo::of(&train_set),
        test: DataInfo::of(&test_set),
        train_seconds: t.seconds,
        threads: 1,
        test_figures: Figures::of(&[1.0], &[1.0]),
        detector: None,
        coverage: None,
        error_model: None,
        sigma_p: 0.05,
    };
    let model = Surrogate::new(info, Predictor::Networks(t.members)).unwrap();
    let file = dir.join("tiny.safetensors");
    model.save(&file).unwrap();
    let back = Surrogate::load(&file).unwrap();
    assert_eq!(back.predictor, model.predictor);
    assert_eq!(back.predict_set(&test_set), model.predict_set(&test_set));
    let volts = [25.0, 1000.0, 2975.0];
    let p = [2.0, 0.5, 0.1];
    assert_eq!(
        back.curve(&p, &volts).unwrap(),
        model.curve(&p, &volts).unwrap()
    );

    // The domain guard and NaN inputs.
    let e = back
        .curve(&[6.0, 0.5, 0.1], &volts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("p0") && e.contains("outside"), "{e}");
    let e = back
        .curve(&[f64::NAN, 0.5, 0.1], &volts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("NaN"), "{e}");
    let e = back.curve(&p, &[5.0]).unwrap_err().to_string();
    assert!(e.contains("U_B"), "{e}");

    // The support guard (issue 24): without a record, estimated from the training-row count
    // (600 rows: 6 must lie beyond, u in [0.01, 0.99]); with one, the 6th-outermost training
    // rows bound it, and the record survives the file.
    assert!(!back.coverage_recorded());
    let [lo, hi] = sp.dimensions[0].range;
    let est = back.support(0);
    assert!((est[0] - (lo + 0.01 * (hi - lo))).abs() < 1e-9, "{est:?}");
    assert!((est[1] - (lo + 0.99 * (hi - lo))).abs() < 1e-9, "{est:?}");
    let mut covered = model.clone();
    covered.info.coverage = Some(Coverage::of(&train_set, &covered.info.inputs));
    let f3 = dir.join("covered.safetensors");
    covered.save(&f3).unwrap();
    let covered = Surrogate::load(&f3).unwrap();
    assert!(covered.coverage_recorded());
    assert_eq!(covered.predict_set(&test_set), model.predict_set(&test_set));
    let mut u0: Vec<f64> = (0..train_set.len())
        .map(|i| train_set.unit_row(i)[0])
        .collect();
    u0.sort_by(f64::total_cmp);
    let c0 = &covered.coverage()[0];
    // (to the last bits: serde_json's float parsing need not round-trip exactly)
    let near =
        |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12;
    assert!(near(c0.u_support, [u0[5], u0[u0.len() - 6]]), "{c0:?}");
    assert!(near(c0.u_extreme, [u0[0], u0[u0.len() - 1]]), "{c0:?}");
    let [slo, shi] = covered.support(0);
    covered.check_support(&p, &[1000.0]).unwrap();
    for x in [lo, slo - 1e-6 * (hi - lo), shi + 1e-6 * (hi - lo), hi] {
        let e = covered
            .check_support(&[x, 0.5, 0.1], &[1000.0])
            .unwrap_err();
        assert!(
            matches!(&e, Error::OutsideSupport { name, .. } if name == "p0"),
            "{e}"
        );
        assert!(!e.is_recoverable());
        // The prediction itself is unchanged: the guard is the caller's.
        covered.curve(&[x, 0.5, 0.1], &[1000.0]).unwrap();
    }
    let e = covered.check_support(&p, &[10.0]).unwrap_err().to_string();
    assert!(
        e.contains("U_B") && e.contains("training rows support"),
        "{e}"
    );

    // A file of another format version.
    let mut other = model.clone();
    other.info.format_version = FORMAT_VERSION + 1;
    let f2 = dir.join("other.safetensors");
    other.save(&f2).unwrap();
    let e = Surrogate::load(&f2).unwrap_err().to_string();
    assert!(e.contains("format_version") && e.contains("retrain"), "{e}");

    // A data set of another space.
    let mut sp2 = sp.clone();
    sp2.dimensions[0].range = [0.1, 5.0];
    let e = DataSet::read(&tr, &sp2).unwrap_err().to_string();
    assert!(e.contains("another space"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The metadata of an untrained unit-test model of [`space`] (sigma_p 1%).
pub(super) fn unit_info() -> ModelInfo {
    let mut info_space = space();
    info_space.name = "test".into();
    ModelInfo {
        format: FORMAT.into(),
        format_version: FORMAT_VERSION,
        program_version: "test".into(),
        space: info_space,
        inputs: vec![],
        input_map: String::new(),
        output: OutputTransform::LogStandardised { mean: 4.0, sd: 0.5 },
        recipe_name: "unit".into(),
        recipe: None,
        seed: 0,
        training: DataInfo {
            file: String::new(),
            hash: String::new(),
            n: 0,
            excluded: 0,
        },
        test: DataInfo {
            file: String::new(),
            hash: String::new(),
            n: 0,
            excluded: 0,
        },
        train_seconds: 0.0,
        threads: 1,
        test_figures: Figures::of(&[1.0], &[1.0]),
        detector: None,
        coverage: None,
        error_model: None,
        sigma_p: 0.01,
    }
}

#[test]
fn physical_jacobian_matches_finite_differences() {
    let arch = Architecture {
        trunk: vec![8],
        head: vec![8],
        steps: None,
        gate: false,
    };
    let net = random_network(&arch, 9);
    let info = unit_info();
    let m = Surrogate::new(
        info,
        Predictor::Networks(vec![net.clone(), random_network(&arch, 10)]),
    )
    .unwrap();
    let u = m.voltages(&[25.0, 800.0, 2500.0]).unwrap();
    let p = [1.7, 0.4, -0.3];
    let (mut c, mut j) = ([0.0; 3], [0.0; 9]);
    m.curve_jacobian_into(&p, &u, &mut c, &mut j).unwrap();
    for k in 0..3 {
        let h = 1e-6 * (1.0 + p[k].abs());
        let (mut a, mut b) = (p, p);
        a[k] += h;
        b[k] -= h;
        let ca = m.curve(&a, &u.volts).unwrap();
        let cb = m.curve(&b, &u.volts).unwrap();
        for v in 0..3 {
            let fd = (ca[v] - cb[v]) / (2.0 * h);
            assert!(
                (fd - j[v * 3 + k]).abs() < 1e-6 * (1.0 + fd.abs()),
                "v {v} k {k}: {fd} vs {}",
                j[v * 3 + k]
            );
        }
    }
}

#[test]
fn a_resumed_ensemble_equals_an_uninterrupted_one() {
    let dir = std::env::temp_dir().join(format!("hpge-surrogate-resume-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sp = space();
    let (tr, te) = (dir.join("train.csv"), dir.join("test.csv"));
    write_set(&tr, &sp, 300, 0);
    write_set(&te, &sp, 80, 1000);
    let train_set = DataSet::read(&tr, &sp).unwrap();
    let test_set = DataSet::read(&te, &sp).unwrap();
    let mut recipe = Recipe::named("tiny").unwrap();
    recipe.members = 2;
    recipe.cycles.truncate(1);
    let mut checkpoints = Vec::new();
    let whole = train_resuming(
        &recipe,
        &train_set,
        &test_set,
        5,
        Vec::new(),
        &mut |_| {},
        &mut |m, member| {
            checkpoints.push((m, member.clone()));
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(checkpoints.len(), 2);
    let first = vec![checkpoints[0].1.clone()];
    let mut epochs = 0;
    let resumed = train_resuming(
        &recipe,
        &train_set,
        &test_set,
        5,
        first,
        &mut |_| epochs += 1,
        &mut |_, _| Ok(()),
    )
    .unwrap();
    assert_eq!(
        epochs,
        recipe.total_epochs(),
        "only the second member is trained"
    );
    assert_eq!(resumed.members, whole.members);
    assert_eq!(resumed.curves.len(), whole.curves.len());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_recipe_adjusted_trains_longer_or_with_another_loss_scale() {
    let split = Recipe::named("split").unwrap();
    assert_eq!(split.clone().adjusted(1.0, None).unwrap(), split);
    let epochs = |r: &Recipe| r.cycles.iter().map(|c| c.epochs).collect::<Vec<_>>();
    assert_eq!(epochs(&split), [10, 150]);

    let longer = split.clone().adjusted(2.5, Some(25.0)).unwrap();
    assert_eq!(epochs(&longer), [25, 375]);
    assert_eq!(longer.loss, Loss::RelativeRobust { h: 25.0 });
    assert_eq!(longer.architecture, split.architecture);
    for (a, b) in longer.cycles.iter().zip(&split.cycles) {
        assert_eq!((a.lr, a.lr_end, a.batch), (b.lr, b.lr_end, b.batch));
    }
    // Never below one epoch per cycle.
    assert_eq!(epochs(&split.clone().adjusted(1e-3, None).unwrap()), [1, 1]);
    // The paper's loss in pF^2 takes an h too.
    let paper = Recipe::named("paper")
        .unwrap()
        .adjusted(1.0, Some(1.0))
        .unwrap();
    assert_eq!(paper.loss, Loss::PaperRobust { h: 1.0 });

    let refused = |r: crate::Result<Recipe>| match r {
        Err(Error::Argument { name, message }) => format!("{name}: {message}"),
        other => panic!("not refused: {other:?}"),
    };
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let m = refused(split.clone().adjusted(bad, None));
        assert!(m.starts_with("--epochs-scale"), "{m}");
    }
    for bad in [0.0, -4.0, f64::NAN] {
        let m = refused(split.clone().adjusted(1.0, Some(bad)));
        assert!(m.starts_with("--loss-h"), "{m}");
    }
    let m = refused(Recipe::named("tiny").unwrap().adjusted(1.0, Some(4.0)));
    assert!(
        m.starts_with("--loss-h") && m.contains("no robust loss"),
        "{m}"
    );
}

#[test]
fn a_tiny_steps_network_trains_reloads_and_falls_with_the_bias() {
    for gate in [false, true] {
        tiny_steps_network_trains_reloads_and_falls(gate);
    }
}

fn tiny_steps_network_trains_reloads_and_falls(gate: bool) {
    let (dir, _, _, _, train_set, test_set) = synthetic_sets(if gate { "gate" } else { "steps" });
    let mut recipe = Recipe::named("tiny-steps").unwrap();
    recipe.architecture.gate = gate;
    let t = train(&recipe, &train_set, &test_set, 2, &mut |_| {}).unwrap();
    let (first, last) = (t.curves.first().unwrap(), t.curves.last().unwrap());
    assert!(
        last.train_loss < 0.5 * first.train_loss && last.test_loss < 0.5 * first.test_loss,
        "{first:?} -> {last:?}"
    );
    let mut info = unit_info();
    info.output = t.output;
    info.recipe_name = recipe.name.clone();
    info.recipe = Some(recipe);
    let model = Surrogate::new(info, Predictor::Networks(t.members)).unwrap();
    let file = dir.join("tiny-steps.safetensors");
    model.save(&file).unwrap();
    let back = Surrogate::load(&file).unwrap();
    assert_eq!(back.predictor, model.predictor);
    assert_eq!(back.predict_set(&test_set), model.predict_set(&test_set));
    let volts: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
    for p in [[2.0, 0.5, 0.1], [0.3, 0.9, -0.8]] {
        let c = back.curve(&p, &volts).unwrap();
        assert!(c.windows(2).all(|w| w[1] <= w[0]), "{c:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
