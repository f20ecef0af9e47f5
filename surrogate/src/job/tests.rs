//! Training runs, checkpoints, evaluation and parameter lists at the library level (the root
//! tests check the same through the binary): a tiny network and the polynomial on a small
//! synthetic set in a temporary folder.

use std::path::{Path, PathBuf};

use super::*;
use crate::Error;
use crate::model::{DataSet, EpochRecord, Surrogate};
use crate::space::ParameterSpace;

/// A fresh temporary folder for one test.
fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hpge-surrogate-job-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Three parameters and the bias; writes the space file into `dir`.
fn space_file(dir: &Path) -> (PathBuf, ParameterSpace) {
    let mut text = String::from("name = \"test\"\n");
    for (k, (lo, hi)) in [(0.2, 5.0), (0.02, 1.0), (-1.0, 1.0)].iter().enumerate() {
        text += &format!(
            "[[dimensions]]\nname = \"p{k}\"\nunit = \"1\"\nrange = [{lo}, {hi}]\ntarget = \"parameter:p{k}\"\n"
        );
    }
    text +=
        "[[dimensions]]\nname = \"U_B\"\nunit = \"V\"\nrange = [10.0, 3000.0]\ntarget = \"bias\"\n";
    let file = dir.join("space.toml");
    std::fs::write(&file, text).unwrap();
    let space = ParameterSpace::from_file(&file).unwrap();
    (file, space)
}

/// A synthetic C-V-like function of (p, U): falls with U, saturates at a p-dependent voltage.
fn synthetic_c12(x: &[f64]) -> f64 {
    let ud = 500.0 + 600.0 * x[0] + 400.0 * x[1];
    let u = x[3].min(ud);
    40.0 * (1.0 + 0.3 * x[2]) * (1.0 + 3.0 * ((ud - u) / ud).powi(2)) + 5.0 * x[1]
}

/// Rows as `generate` writes them (one failed solve at the end, left out when read).
fn write_set(path: &Path, sp: &ParameterSpace, n: usize, offset: usize) {
    let g = |i: usize, k: usize| {
        ((i as f64 + 0.5) * [0.7548776662, 0.5698402910, 0.4301597090, 0.3247179572][k]).fract()
    };
    let mut text =
        String::from("index,u_p0,u_p1,u_p2,u_U_B,p0,p1,p2,U_B,c12_pF,status,c12_err_pF,seconds\n");
    for i in offset..=offset + n {
        let u: Vec<f64> = (0..4).map(|k| g(i, k)).collect();
        let x = sp.from_unit(&u);
        let row: Vec<String> = u.iter().chain(&x).map(|v| v.to_string()).collect();
        if i == offset + n {
            text += &format!("{i},{},NaN,failed: test,NaN,0.1\n", row.join(","));
        } else {
            text += &format!("{i},{},{},ok,0.001,0.1\n", row.join(","), synthetic_c12(&x));
        }
    }
    std::fs::write(path, text).unwrap();
}

/// A job on a fresh synthetic training and test set in `dir`.
fn job(dir: &Path, recipe: &str, seed: u64) -> TrainJob {
    let (space, sp) = space_file(dir);
    let (data, test) = (dir.join("train.csv"), dir.join("test.csv"));
    write_set(&data, &sp, 240, 0);
    write_set(&test, &sp, 60, 1000);
    TrainJob {
        data,
        test,
        space,
        recipe: recipe.into(),
        seed,
        detector: None,
        out: dir.join(format!("{recipe}.safetensors")),
        epochs_scale: DEFAULT_EPOCHS_SCALE,
        loss_h: None,
        trunk: None,
        head: None,
        members: None,
        weight_decay: None,
    }
}

/// The events of a run, in words.
fn run_logged(job: &TrainJob) -> (crate::Result<TrainOutcome>, Vec<String>) {
    let mut log = Vec::new();
    let r = job.run(&mut |e| {
        log.push(match e {
            TrainEvent::DataRead { train, test } => format!("data {} {}", train.len(), test.len()),
            TrainEvent::NetworksStart {
                total_epochs,
                resumed_epochs,
                resumed,
                members,
                ..
            } => format!("start {total_epochs} {resumed_epochs} {resumed} {members}"),
            TrainEvent::Epoch(r) => format!("epoch {}", r.epoch),
            TrainEvent::NetworksDone => "done".into(),
        })
    });
    (r, log)
}

fn losses(curves_file: &Path) -> Vec<f64> {
    std::fs::read_to_string(curves_file)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("member"))
        .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn a_tiny_network_trains_writes_its_files_and_resumes_from_a_checkpoint() {
    let d = temp("tiny");
    let job = job(&d, "tiny", 3);
    let (outcome, log) = run_logged(&job);
    let outcome = outcome.unwrap();
    let epochs: Vec<String> = (1..=12).map(|e| format!("epoch {e}")).collect();
    assert_eq!(log[0], "data 240 60");
    assert_eq!(log[1], "start 12 0 0 1");
    assert_eq!(log[2..14], epochs[..]);
    assert_eq!(log[14..], ["done"]);

    // The model file: the metadata of the run, the test figures, reloading to the same numbers.
    let model = Surrogate::load(&job.out).unwrap();
    let info = &model.info;
    assert_eq!(info.recipe_name, "tiny");
    assert_eq!(info.seed, 3);
    assert_eq!(info.program_version, env!("CARGO_PKG_VERSION"));
    assert_eq!(info.inputs, ["p0", "p1", "p2", "U_B"]);
    assert_eq!((info.training.n, info.training.excluded), (240, 1));
    assert_eq!((info.test.n, info.test.excluded), (60, 1));
    assert_eq!(info.test_figures.n, 60);
    assert_eq!(info.sigma_p, info.test_figures.rel_sigma);
    assert_eq!(info.detector, None);
    assert_eq!(model.predictor, outcome.model.predictor);
    let test = DataSet::read(&job.test, &model.info.space).unwrap();
    assert_eq!(model.predict_set(&test), outcome.test_predictions);
    assert_eq!(outcome.test_c12_pf, test.c12_pf);

    // The learning curves: the header, one line per epoch, the training loss falls.
    let curves_file = d.join("tiny.curves.csv");
    assert_eq!(outcome.curves_file.as_deref(), Some(curves_file.as_path()));
    assert_eq!(curves_path(&job.out), curves_file);
    let text = std::fs::read_to_string(&curves_file).unwrap();
    let mut lines = text.lines();
    // A plain table (issue 22): the header first, no comment lines; the provenance in the
    // sidecar tiny.curves.json.
    assert_eq!(
        lines.next().unwrap(),
        "member,epoch,cycle,lr,train_loss,test_loss,test_rel_rms,seconds"
    );
    assert!(!text.lines().any(|l| l.starts_with('#')), "{text}");
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("tiny.curves.json")).unwrap())
            .unwrap();
    assert_eq!(sidecar["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(sidecar["model"], job.out.display().to_string());
    let l = losses(&curves_file);
    assert_eq!(l.len(), 12);
    assert!(l[11] < 0.5 * l[0], "{l:?}");
    assert_eq!(outcome.curves.len(), 12);

    // Resume: a finished member waiting in NAME.partial/ is taken, not retrained, and the result
    // is the same model; the checkpoints go once the model is written.
    let partial = d.join("tiny.partial");
    assert_eq!(partial_dir(&job.out), partial);
    let checkpoint = || {
        std::fs::create_dir_all(&partial).unwrap();
        std::fs::copy(&job.out, partial.join("member-0.safetensors")).unwrap();
        std::fs::copy(&curves_file, partial.join("member-0.curves.csv")).unwrap();
    };
    checkpoint();
    let (again, log) = run_logged(&job);
    let again = again.unwrap();
    assert_eq!(log, ["data 240 60", "start 12 12 1 1", "done"]);
    assert!(!partial.exists(), "checkpoints are removed");
    assert_eq!(again.model.predictor, outcome.model.predictor);
    assert_eq!(
        again.model.info.test_figures,
        outcome.model.info.test_figures
    );
    assert_eq!(losses(&curves_file), l);

    // A checkpoint of another run (another seed, or the same recipe trained longer) is refused,
    // naming the file.
    checkpoint();
    let longer = TrainJob {
        epochs_scale: 2.0,
        ..job.clone()
    };
    for other in [
        TrainJob {
            seed: 4,
            ..job.clone()
        },
        longer.clone(),
    ] {
        let e = other.run(&mut |_| {}).unwrap_err();
        assert!(matches!(e, Error::Checkpoint { .. }), "{e:?}");
        let text = e.to_string();
        assert!(
            text.contains("member-0.safetensors") && text.contains("another run"),
            "{text}"
        );
    }

    // tiny's loss is the squared relative error, which has no scale h: --loss-h is refused by
    // name before any training.
    let e = TrainJob {
        loss_h: Some(25.0),
        ..longer.clone()
    }
    .run(&mut |_| {})
    .unwrap_err();
    assert!(
        matches!(&e, Error::Argument { name, .. } if name == "--loss-h"),
        "{e:?}"
    );

    // Trained twice as long: 24 epochs, recorded in the model file.
    std::fs::remove_dir_all(&partial).unwrap();
    let (outcome, log) = run_logged(&longer);
    outcome.unwrap();
    assert_eq!(log[1], "start 24 0 0 1");
    assert_eq!(log.len(), 2 + 24 + 1);
    let recipe = Surrogate::load(&longer.out).unwrap().info.recipe.unwrap();
    let epochs: Vec<usize> = recipe.cycles.iter().map(|c| c.epochs).collect();
    assert_eq!(epochs, [8, 16]);
    let _ = std::fs::remove_dir_all(&d);
}

/// `--trunk`, `--head` and `--members` reshape the recipe: the model file records (and loads
/// with) the widths and members as trained; a zero width or no members is refused by name.
#[test]
fn the_recipes_widths_and_members_can_be_replaced() {
    let d = temp("reshape");
    let job = TrainJob {
        trunk: Some(vec![8, 8]),
        head: Some(vec![4]),
        members: Some(2),
        ..job(&d, "tiny", 3)
    };
    let (outcome, log) = run_logged(&job);
    outcome.unwrap();
    assert_eq!(log[1], "start 24 0 0 2", "two members of 12 epochs");
    let model = Surrogate::load(&job.out).unwrap();
    let recipe = model.info.recipe.clone().unwrap();
    assert_eq!(recipe.architecture.trunk, [8, 8]);
    assert_eq!(recipe.architecture.head, [4]);
    assert_eq!(recipe.members, 2);
    let crate::model::Predictor::Networks(nets) = &model.predictor else {
        panic!("networks")
    };
    assert_eq!(nets.len(), 2);
    for (bad, name) in [
        (
            TrainJob {
                members: Some(0),
                ..job.clone()
            },
            "--members",
        ),
        (
            TrainJob {
                head: Some(vec![4, 0]),
                ..job.clone()
            },
            "--head 4,0",
        ),
        (
            TrainJob {
                weight_decay: Some(-0.1),
                ..job.clone()
            },
            "--weight-decay",
        ),
    ] {
        let e = bad.recipe().unwrap_err();
        assert!(
            matches!(&e, Error::Argument { name: n, .. } if n == name),
            "{e:?}"
        );
    }
    let e = TrainJob {
        recipe: POLYNOMIAL_RECIPE.into(),
        ..job.clone()
    }
    .recipe()
    .unwrap_err();
    assert!(e.to_string().contains("--members"), "{e}");

    // Weight decay is recorded in the model file and changes the weights it trains.
    let decayed = TrainJob {
        weight_decay: Some(0.5),
        members: Some(1),
        out: d.join("decayed.safetensors"),
        ..job.clone()
    };
    let plain = TrainJob {
        members: Some(1),
        out: d.join("plain.safetensors"),
        ..job.clone()
    };
    decayed.run(&mut |_| {}).unwrap();
    plain.run(&mut |_| {}).unwrap();
    let (a, b) = (
        Surrogate::load(&decayed.out).unwrap(),
        Surrogate::load(&plain.out).unwrap(),
    );
    assert_eq!(a.info.recipe.as_ref().unwrap().weight_decay, 0.5);
    assert_eq!(b.info.recipe.as_ref().unwrap().weight_decay, 0.0);
    assert_ne!(a.predictor, b.predictor);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_ensembles_members_checkpoint_and_resume_one_by_one() {
    let d = temp("ensemble");
    let tiny = job(&d, "tiny", 5);
    tiny.run(&mut |_| {}).unwrap();
    let model = Surrogate::load(&tiny.out).unwrap();
    let crate::model::Predictor::Networks(nets) = &model.predictor else {
        panic!("a network")
    };
    let curves: Vec<EpochRecord> = model_curves(&tiny.out.with_extension("curves.csv"));
    // A two-member model's info; member 1 a copy of member 0 with its own curves.
    let mut info = model.info.clone();
    if let Some(r) = info.recipe.as_mut() {
        r.members = 2;
    }
    let partial = d.join("ensemble.partial");
    let second: Vec<EpochRecord> = curves
        .iter()
        .map(|r| EpochRecord { member: 1, ..*r })
        .collect();
    save_member(&partial, &info, 0, &(nets[0].clone(), curves.clone())).unwrap();
    assert_eq!(resume_members(&partial, &info).unwrap().len(), 1);
    save_member(&partial, &info, 1, &(nets[0].clone(), second.clone())).unwrap();
    let back = resume_members(&partial, &info).unwrap();
    assert_eq!(back.len(), 2);
    for (m, (net, c)) in back.iter().enumerate() {
        assert_eq!(net, &nets[0]);
        let expected = if m == 0 { &curves } else { &second };
        assert_eq!(c.len(), expected.len());
        for (a, b) in c.iter().zip(expected) {
            assert_eq!((a.member, a.epoch, a.cycle), (b.member, b.epoch, b.cycle));
            assert_eq!(
                (a.lr, a.train_loss, a.test_loss),
                (b.lr, b.train_loss, b.test_loss)
            );
        }
    }
    // No folder, no members; a torn curves file is refused.
    assert!(resume_members(&d.join("none"), &info).unwrap().is_empty());
    std::fs::write(partial.join("member-1.curves.csv"), "member,epoch\n1,2,3\n").unwrap();
    let e = resume_members(&partial, &info).unwrap_err().to_string();
    assert!(
        e.contains("member-1.curves.csv") && e.contains("malformed"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

fn model_curves(file: &Path) -> Vec<EpochRecord> {
    let text = std::fs::read_to_string(file).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("member"))
        .map(|l| EpochRecord::from_csv_line(l).expect("eight numbers"))
        .collect()
}

#[test]
fn the_polynomial_writes_no_curves_and_evaluates() {
    let d = temp("poly");
    let job = job(&d, POLYNOMIAL_RECIPE, 0);
    let (outcome, log) = run_logged(&job);
    let outcome = outcome.unwrap();
    assert_eq!(log, ["data 240 60"]);
    assert!(outcome.curves.is_empty() && outcome.curves_file.is_none());
    assert!(!d.join("poly3.curves.csv").exists());
    let model = Surrogate::load(&job.out).unwrap();
    assert_eq!(model.info.recipe, None);

    // Evaluation: the test figures of the model file, the worst samples worst first.
    let data = read_for_model(&model, &job.out, &job.test).unwrap();
    let ev = Evaluation::new(&model, &data, 3);
    assert_eq!(ev.figures, model.info.test_figures);
    assert_eq!(ev.excluded, 1);
    assert_eq!(ev.worst.len(), 3);
    assert!(ev.worst[0].rel.abs() >= ev.worst[1].rel.abs());
    assert!(ev.worst[1].rel.abs() >= ev.worst[2].rel.abs());
    let max = ev.worst[0].rel.abs();
    assert!((max - ev.figures.abs_rel_max).abs() <= 1e-15 * max, "{max}");
    assert_eq!(ev.worst[0].inputs.len(), 4);
    let json = serde_json::to_string(&ev.json(&job.out, &job.test)).unwrap();
    let keys = [
        "n",
        "rel_sigma",
        "rel_mean",
        "abs_rel_q50",
        "abs_rel_q90",
        "abs_rel_q99",
        "abs_rel_max",
        "abs_rel_q999",
        "rel_rms",
        "abs_rms_pf",
        "excluded",
        "model",
        "data",
        "data_hash",
        "recipe",
        "sigma_p",
        "worst",
        "program_version",
    ];
    let at: Vec<usize> = keys
        .iter()
        .map(|k| json.find(&format!("\"{k}\":")).unwrap())
        .collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{json}");
    assert!(json.contains("\"recipe\":\"poly3\""), "{json}");
    assert!(json.contains("\"worst\":[{\"index\":"), "{json}");
    assert!(json.contains("\"inputs\":[[\"p0\","), "{json}");

    // A data set of another space names the model and its space.
    let text = std::fs::read_to_string(&job.test)
        .unwrap()
        .replacen("u_p1", "u_q1", 1);
    let other = d.join("other.csv");
    std::fs::write(&other, text).unwrap();
    let e = read_for_model(&model, &job.out, &other)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("other.csv") && e.contains("another space"),
        "{e}"
    );
    assert!(
        e.ends_with(&format!(
            "\n(the model {} was trained on space `test`)",
            job.out.display()
        )),
        "{e}"
    );

    // Calibration (issue 21): refused on the model's own training or test set; on rows it never
    // saw it writes the error model into a copy, predictions unchanged, and evaluate reports the
    // per-point coverage.
    let cal_out = d.join("calibrated.safetensors");
    for own in [&job.data, &job.test] {
        let e = CalibrateOptions {
            model: job.out.clone(),
            data: own.clone(),
            out: Some(cal_out.clone()),
            no_gate_input: false,
        }
        .run()
        .unwrap_err();
        assert!(
            matches!(e, Error::Argument { .. }) && e.to_string().contains("never saw"),
            "{e}"
        );
    }
    assert!(!cal_out.exists());
    let fresh = d.join("fresh.csv");
    write_set(&fresh, &model.info.space, 200, 5000);
    let cal = CalibrateOptions {
        model: job.out.clone(),
        data: fresh.clone(),
        out: Some(cal_out.clone()),
        no_gate_input: false,
    };
    let em = cal.run().unwrap();
    assert!(em.calibration.n > 150, "{}", em.calibration.n);
    let calibrated = Surrogate::load(&cal_out).unwrap();
    assert_eq!(calibrated.predictor, model.predictor);
    assert_eq!(calibrated.info.error_model.as_ref(), Some(&em));
    let rows = read_for_model(&calibrated, &cal_out, &fresh).unwrap();
    let ev = Evaluation::new(&calibrated, &rows, 0);
    assert_eq!(ev.sigma_kind, "per-point");
    assert!((ev.coverage.1 - 0.9545).abs() < 0.01, "{:?}", ev.coverage);
    let plain = Evaluation::new(&model, &rows, 0);
    assert_eq!((plain.sigma_kind, plain.figures), ("constant", ev.figures));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_jobs_are_refused_with_the_file_at_fault() {
    let d = temp("bad");
    let good = job(&d, "tiny", 1);
    let message = |j: &TrainJob| j.run(&mut |_| {}).unwrap_err().to_string();
    let e = message(&TrainJob {
        out: d.join("model.bin"),
        ..good.clone()
    });
    assert_eq!(
        e,
        format!(
            "{}: the model file must end in .safetensors",
            d.join("model.bin").display()
        )
    );
    let e = message(&TrainJob {
        out: d.join("missing").join("m.safetensors"),
        ..good.clone()
    });
    assert!(e.ends_with(&format!(
        "the folder {} does not exist",
        d.join("missing").display()
    )));
    let e = message(&TrainJob {
        recipe: "huge".into(),
        ..good.clone()
    });
    assert!(e.contains("unknown recipe") && e.contains("paper"), "{e}");
    let text = std::fs::read_to_string(&good.data)
        .unwrap()
        .replacen("u_p1", "u_q1", 1);
    let other = d.join("other.csv");
    std::fs::write(&other, text).unwrap();
    let e = message(&TrainJob {
        data: other,
        ..good.clone()
    });
    assert!(
        e.contains("other.csv") && e.contains("another space"),
        "{e}"
    );
    assert!(!good.out.exists(), "nothing written");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn parameter_lists_by_name_or_in_order() {
    let d = temp("params");
    let job = job(&d, POLYNOMIAL_RECIPE, 0);
    job.run(&mut |_| {}).unwrap();
    let model = Surrogate::load(&job.out).unwrap();
    let items = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let p = |s: &[&str]| parse_params(&model, &items(s));
    assert_eq!(p(&["p2=0.5, p0=1", "p1=0.1"]).unwrap(), [1.0, 0.1, 0.5]);
    assert_eq!(p(&["1,0.1", "0.5"]).unwrap(), [1.0, 0.1, 0.5]);
    let e = |s: &[&str]| {
        let e = p(s).unwrap_err();
        assert!(matches!(e, Error::Parameters { .. }), "{e:?}");
        e.to_string()
    };
    assert_eq!(
        e(&["p0=1,0.1,p2=0.5"]),
        "`0.1` is not NAME=VALUE (do not mix names and bare values)"
    );
    assert_eq!(
        e(&["p0=1,p1=0.1,q=0.5"]),
        "unknown parameter `q`; the model takes p0, p1, p2"
    );
    assert_eq!(
        e(&["p0=1,p1=0.1"]),
        "no value for `p2`; the model takes p0, p1, p2"
    );
    assert_eq!(
        e(&["1,2"]),
        "2 values given, the model takes 3 (p0, p1, p2)"
    );
    assert_eq!(e(&["1,x,2"]), "`x` (for p1) is not a number");
    assert_eq!(e(&["p0=1,p1=y,p2=2"]), "`y` (for p1) is not a number");
    assert_eq!(e(&["nan,nan,nan"]), "`p0` = NaN is not a finite number");
    // A named value that is not finite is named as such, not as missing (issue 24, group 10).
    assert_eq!(
        e(&["p0=nan,p1=0.1,p2=0.5"]),
        "`p0` = NaN is not a finite number"
    );
    // A parameter given twice is refused, not the last one silently taken (issue 24, group 9).
    assert_eq!(
        e(&["p0=1,p1=0.1,p2=0.5", "p0=2"]),
        "`p0` is given twice; give each parameter once"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_test_set_must_not_be_the_training_set() {
    let d = temp("same");
    let mut job = job(&d, POLYNOMIAL_RECIPE, 0);
    job.test = job.data.clone();
    let e = job.run(&mut |_| {}).unwrap_err().to_string();
    assert!(
        e.contains("--test") && e.contains("training set itself"),
        "{e}"
    );
    assert!(!job.out.exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_polynomial_needs_as_many_rows_as_coefficients() {
    let d = temp("poly-few");
    let (space, sp) = space_file(&d);
    let (data, test) = (d.join("one.csv"), d.join("test.csv"));
    write_set(&data, &sp, 1, 0);
    write_set(&test, &sp, 60, 1000);
    let job = TrainJob {
        data,
        test,
        space,
        recipe: POLYNOMIAL_RECIPE.into(),
        seed: 0,
        detector: None,
        out: d.join("poly3.safetensors"),
        epochs_scale: DEFAULT_EPOCHS_SCALE,
        loss_h: None,
        trunk: None,
        head: None,
        members: None,
        weight_decay: None,
    };
    let e = job.run(&mut |_| {}).unwrap_err().to_string();
    assert!(
        e.contains("one.csv") && e.contains("1 rows") && e.contains("35"),
        "{e}"
    );
    assert!(!job.out.exists());
    let _ = std::fs::remove_dir_all(&d);
}
