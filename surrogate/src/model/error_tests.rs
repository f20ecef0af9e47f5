//! Unit tests of the per-point uncertainty: recovery of a known heteroscedastic sigma, its
//! calibration, its derivatives, and the model file round trip.

use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};

use super::tests::{random_network, unit_info};
use super::*;
use crate::Error;

fn info() -> DataInfo {
    DataInfo {
        file: "synthetic".into(),
        hash: "0".into(),
        n: 0,
        excluded: 0,
    }
}

/// n rows of 2 inputs z ~ N(0, 1) with relative errors r ~ N(0, sigma(z)),
/// ln sigma^2 = ln 1e-4 + 0.6 z_1 + 0.3 z_2^2.
fn synthetic(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut z = Vec::with_capacity(2 * n);
    let mut r = Vec::with_capacity(n);
    for _ in 0..n {
        let (a, b): (f64, f64) = (
            StandardNormal.sample(&mut rng),
            StandardNormal.sample(&mut rng),
        );
        let s = (1e-4f64.ln() + 0.6 * a + 0.3 * b * b)
            .mul_add(0.5, 0.0)
            .exp();
        let e: f64 = StandardNormal.sample(&mut rng);
        z.extend([a, b]);
        r.push(s * e);
    }
    (z, r)
}

#[test]
fn the_fit_recovers_a_known_heteroscedastic_sigma_and_calibrates_its_coverage() {
    let (z, r) = synthetic(20000, 3);
    let m = ErrorModel::fit(vec!["a".into(), "b".into()], &z, &r, info()).unwrap();
    // w = [w_0, a_1, b_1, a_2, b_2]; kappa absorbs only the heavy-tail correction (none here).
    let truth = [1e-4f64.ln(), 0.6, 0.0, 0.0, 0.3];
    for (k, (w, t)) in m.weights.iter().zip(truth).enumerate() {
        assert!((w - t).abs() < 0.06, "weight {k}: {w} vs {t}");
    }
    assert!((m.kappa - 1.0).abs() < 0.05, "kappa {}", m.kappa);
    assert!((m.coverage_2sigma - TARGET_COVERAGE_2SIGMA).abs() < 1e-3);
    assert!(
        (m.coverage_1sigma - 0.6827).abs() < 0.015,
        "{}",
        m.coverage_1sigma
    );
    // On fresh rows of the same law the coverage holds too.
    let (z2, r2) = synthetic(20000, 4);
    let (c1, c2) = m.coverage(&z2, &r2);
    assert!(
        (c1 - 0.6827).abs() < 0.015 && (c2 - 0.9545).abs() < 0.01,
        "{c1} {c2}"
    );
    // A constant sigma of the same overall size covers the wide rows too little.
    let rms = (r2.iter().map(|x| x * x).sum::<f64>() / r2.len() as f64).sqrt();
    let wide: Vec<usize> = (0..r2.len()).filter(|&i| z2[2 * i] > 1.5).collect();
    let within = |s: &dyn Fn(usize) -> f64| {
        wide.iter().filter(|&&i| r2[i].abs() <= 2.0 * s(i)).count() as f64 / wide.len() as f64
    };
    let per_point = within(&|i| m.sigma(&z2[2 * i..2 * i + 2], None));
    let constant = within(&|_| rms);
    assert!(
        per_point > 0.93 && constant < per_point - 0.05,
        "{per_point} {constant}"
    );
}

#[test]
fn heavier_tails_get_a_kappa_above_one() {
    let (z, mut r) = synthetic(5000, 5);
    let mut rng = rand::rngs::StdRng::seed_from_u64(6);
    for x in r.iter_mut() {
        if rng.random::<f64>() < 0.08 {
            *x *= 6.0;
        }
    }
    let m = ErrorModel::fit(vec!["a".into(), "b".into()], &z, &r, info()).unwrap();
    assert!((m.coverage_2sigma - TARGET_COVERAGE_2SIGMA).abs() < 1e-3);
    assert!(m.coverage_1sigma > 0.72, "{}", m.coverage_1sigma);
}

#[test]
fn sigma_and_its_gradient_agree_with_finite_differences_and_respect_the_cap() {
    let m = ErrorModel {
        inputs: vec!["a".into(), "b".into()],
        weights: vec![-9.0, 0.4, 0.2, -0.3, 0.1],
        kappa: 1.3,
        calibration: info(),
        coverage_1sigma: 0.7,
        coverage_2sigma: 0.95,
        iterations: 1,
    };
    let z = [0.7, -1.2];
    let mut g = [0.0; 2];
    let s = m.sigma(&z, Some(&mut g));
    let expect = 1.3 * (0.5 * (-9.0 + 0.4 * 0.7 + 0.2 * 0.49 - 0.3 * -1.2 + 0.1 * 1.44f64)).exp();
    assert!((s - expect).abs() < 1e-15 * expect.max(1.0));
    for j in 0..2 {
        let h = 1e-6;
        let (mut a, mut b) = (z, z);
        a[j] += h;
        b[j] -= h;
        let fd = (m.sigma(&a, None).powi(2) - m.sigma(&b, None).powi(2)) / (2.0 * h);
        assert!(
            (fd - g[j]).abs() < 1e-6 * fd.abs().max(1e-12),
            "{j}: {fd} vs {}",
            g[j]
        );
    }
    // Far out the cap holds, with zero derivative.
    let s = m.sigma(&[40.0, 0.0], Some(&mut g));
    assert_eq!(s, SIGMA_MAX);
    assert_eq!(g, [0.0, 0.0]);
}

#[test]
fn bad_calibration_sets_are_errors() {
    let names = vec!["a".to_string()];
    let e = ErrorModel::fit(names.clone(), &[0.0; 4], &[0.01; 4], info()).unwrap_err();
    assert!(matches!(e, Error::Training { .. }) && e.to_string().contains("at least 6"));
    let e = ErrorModel::fit(
        names,
        &[0.0; 8],
        &[0.01, f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        info(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("row 1"), "{e}");
}

/// `jac` (voltages x 3, from `curve_variance_into`) against central differences of sigma_s^2
/// in each of the 3 parameters: |fd - jac| < rel max(|fd|, floor).
fn assert_variance_jacobian(
    m: &Surrogate,
    p: [f64; 3],
    u: &crate::model::Voltages,
    jac: &[f64],
    rel: f64,
    floor: f64,
) {
    let nv = u.z.len();
    for k in 0..3 {
        let h = 1e-6 * (1.0 + p[k].abs());
        let (mut a, mut b) = (p, p);
        a[k] += h;
        b[k] -= h;
        let (mut va, mut vb) = (vec![0.0; nv], vec![0.0; nv]);
        m.curve_variance_into(&a, u, &mut va, None).unwrap();
        m.curve_variance_into(&b, u, &mut vb, None).unwrap();
        for q in 0..nv {
            let fd = (va[q] - vb[q]) / (2.0 * h);
            assert!(
                (fd - jac[q * 3 + k]).abs() < rel * fd.abs().max(floor),
                "{q} {k}: {fd} vs {}",
                jac[q * 3 + k]
            );
        }
    }
}

fn calibrated() -> Surrogate {
    let recipe = Recipe::named("tiny").unwrap();
    let arch = recipe.architecture.clone();
    let mut info = unit_info();
    info.recipe = Some(recipe);
    info.error_model = Some(ErrorModel {
        inputs: vec!["p0".into(), "p1".into(), "p2".into(), "U_B".into()],
        weights: vec![-8.0, 0.1, 0.05, -0.2, 0.02, 0.3, 0.1, -0.4, 0.15],
        kappa: 1.1,
        calibration: info.test.clone(),
        coverage_1sigma: 0.7,
        coverage_2sigma: 0.9545,
        iterations: 1,
    });
    Surrogate::new(info, Predictor::Networks(vec![random_network(&arch, 4)])).unwrap()
}

#[test]
fn the_curve_variance_has_the_right_jacobian_and_falls_back_to_sigma_p() {
    let m = calibrated();
    let u = m.voltages(&[25.0, 800.0, 2500.0]).unwrap();
    let p = [1.7, 0.4, -0.3];
    let (mut v, mut j) = ([0.0; 3], [0.0; 9]);
    m.curve_variance_into(&p, &u, &mut v, Some(&mut j)).unwrap();
    let mut v0 = [0.0; 3];
    m.curve_variance_into(&p, &u, &mut v0, None).unwrap();
    assert_eq!(v, v0);
    assert!(v[0] != v[2], "per point: {v:?}");
    assert_variance_jacobian(&m, p, &u, &j, 1e-6, 1e-14);
    // Outside the domain: the domain guard's error.
    assert!(
        m.curve_variance_into(&[9.0, 0.4, 0.0], &u, &mut v, None)
            .is_err()
    );
    // Without an error model: sigma_p^2, zero derivatives.
    let mut plain = m.clone();
    plain.info.error_model = None;
    plain
        .curve_variance_into(&p, &u, &mut v, Some(&mut j))
        .unwrap();
    assert_eq!(v, [1e-4; 3]);
    assert!(j.iter().all(|&x| x == 0.0));
}

#[test]
fn a_calibrated_model_file_reloads_with_its_error_model_and_unchanged_predictions() {
    let dir = std::env::temp_dir().join(format!("hpge-error-model-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("m.safetensors");
    // As `calibrate` does: a model read from its file (f32 weights) written again.
    calibrated().save(&file).unwrap();
    let m = Surrogate::load(&file).unwrap();
    m.save(&file).unwrap();
    let back = Surrogate::load(&file).unwrap();
    assert_eq!(back.predictor, m.predictor);
    assert_eq!(back.info.error_model, m.info.error_model);
    let volts = [25.0, 1000.0];
    let p = [2.0, 0.5, 0.1];
    assert_eq!(
        back.curve(&p, &volts).unwrap(),
        m.curve(&p, &volts).unwrap()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A gated surrogate's error model takes the gate's proximity as a fifth input; its variance's
/// Jacobian (through z_p and through e(z_p)) matches central differences, and the same error
/// model on a network without the gate is not used.
#[test]
fn a_gated_surrogate_feeds_the_gate_proximity_to_sigma_s() {
    let mut recipe = Recipe::named("tiny-steps").unwrap();
    recipe.architecture.gate = true;
    let arch = recipe.architecture.clone();
    let mut info = unit_info();
    info.recipe = Some(recipe);
    info.error_model = Some(ErrorModel {
        inputs: vec![
            "p0".into(),
            "p1".into(),
            "p2".into(),
            "U_B".into(),
            super::uncertainty::GATE_INPUT.into(),
        ],
        weights: vec![-8.0, 0.1, 0.05, -0.2, 0.02, 0.3, 0.1, -0.4, 0.15, 3.0, 1.0],
        kappa: 1.1,
        calibration: info.test.clone(),
        coverage_1sigma: 0.7,
        coverage_2sigma: 0.9545,
        iterations: 1,
    });
    let mut net = random_network(&arch, 7);
    // Place the gate inside the bias range (its place output's bias: v_g = 1.25 + 0.5 b).
    let gate_place = net.out.b.len() - 3;
    net.out.b[gate_place] = -1.0;
    let m = Surrogate::new(info.clone(), Predictor::Networks(vec![net])).unwrap();
    assert!(m.has_gate() && m.error_model().is_some());
    let u = m.voltages(&[25.0, 300.0, 800.0, 2500.0]).unwrap();
    let p = [1.7, 0.4, -0.3];
    let (mut v, mut j) = ([0.0; 4], [0.0; 12]);
    m.curve_variance_into(&p, &u, &mut v, Some(&mut j)).unwrap();
    let mut v0 = [0.0; 4];
    m.curve_variance_into(&p, &u, &mut v0, None).unwrap();
    assert_eq!(v, v0);
    // The gate's input matters here: without its weights sigma_s^2 is smaller near the gate.
    let mut blind = m.clone();
    let w = &mut blind.info.error_model.as_mut().unwrap().weights;
    w[9] = 0.0;
    w[10] = 0.0;
    let mut vb0 = [0.0; 4];
    blind.curve_variance_into(&p, &u, &mut vb0, None).unwrap();
    assert!(
        v.iter().zip(&vb0).any(|(a, b)| a > &(1.5 * b)),
        "{v:?} vs {vb0:?}"
    );
    assert_variance_jacobian(&m, p, &u, &j, 1e-5, 1e-12);
    // Calibrated on rows: the gate's proximity is an input unless left out.
    let (dir, _, _, _, _, test_set) = super::tests::synthetic_sets("gate-input");
    let with = m.fit_error_model(&test_set).unwrap();
    assert_eq!(with.inputs.last().unwrap(), super::uncertainty::GATE_INPUT);
    let without = m.fit_error_model_with(&test_set, false).unwrap();
    assert_eq!(without.inputs.len(), 4);
    let _ = std::fs::remove_dir_all(&dir);
    // The same error model on a steps network without the gate: not used (sigma_p instead).
    let mut plain_recipe = Recipe::named("tiny-steps").unwrap();
    plain_recipe.architecture.gate = false;
    let plain_arch = plain_recipe.architecture.clone();
    info.recipe = Some(plain_recipe);
    let plain = Surrogate::new(
        info,
        Predictor::Networks(vec![random_network(&plain_arch, 7)]),
    )
    .unwrap();
    assert!(!plain.has_gate() && plain.error_model().is_none());
}
