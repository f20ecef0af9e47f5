//! Issue 18, part 3: the error estimate of c12 and the adaptive refinement, at CI-sized settings.
//! The full table (default tolerance, every detector type, 4x finer references) is
//! `cargo run --release -p hpge-validation --example accuracy_table` (reports/accuracy/).

use hpge_solver::field::solve_point_on_grid;
use hpge_solver::{Detector, FieldSettings, Parameters, cv_curve, solve_point};
use hpge_validation::{LongCoax, accuracy_cases, accuracy_row, repo_path};

fn detector(name: &str) -> Detector {
    Detector::from_file(&repo_path(name), &Parameters::new()).unwrap()
}

/// CI-sized settings: twice the default spacings, a 1% tolerance.
fn ci_settings() -> FieldSettings {
    let mut s = FieldSettings::default();
    s.grid.max_spacing_semiconductor_mm = 2.0;
    s.grid.max_spacing_mm = 8.0;
    s.grid.front_spacing_mm = 0.5;
    s.grid.tolerance = 1e-2;
    s
}

/// Against the closed form of the long coax: every point within 1.5x its tolerance, and its
/// estimate at least the actual error (or within 1.5x of it).
#[test]
fn estimate_bounds_the_long_coax_error() {
    let det = detector("detectors/coax-analytic.toml");
    let exact = LongCoax::validation();
    for tolerance in [1e-2, 2e-3] {
        let mut s = FieldSettings::default();
        s.grid.tolerance = tolerance;
        for v in [25.0, 275.0, 1025.0, 2975.0] {
            let p = solve_point(&det, v, &s, None).unwrap();
            let want = 10.0 * exact.c12_per_mm_pf(v).unwrap();
            let actual = (p.c12_pf / want - 1.0).abs();
            let estimate = p.accuracy.c12_err_pf / p.c12_pf;
            assert!(p.accuracy.reached, "{v} V, tolerance {tolerance}");
            assert!(
                actual <= 1.5 * tolerance && 1.5 * estimate >= actual,
                "{v} V, tolerance {tolerance}: actual {actual:.2e}, estimate {estimate:.2e}"
            );
        }
    }
}

/// A tighter tolerance gives a finer grid and a smaller estimate; adaptivity off keeps the
/// potential's grid and still reports its estimate.
#[test]
fn a_tighter_tolerance_refines() {
    let det = detector("detectors/ppc.toml");
    let mut loose = ci_settings();
    loose.grid.tolerance = 5e-2;
    let mut tight = ci_settings();
    tight.grid.tolerance = 5e-3;
    let a = solve_point(&det, 4000.0, &loose, None).unwrap();
    let b = solve_point(&det, 4000.0, &tight, None).unwrap();
    assert!(a.accuracy.reached && b.accuracy.reached);
    assert!(b.mesh.grid.len() > a.mesh.grid.len());
    assert!(b.accuracy.passes > a.accuracy.passes);
    assert!(b.accuracy.c12_err_pf / b.c12_pf <= 5e-3);
    let mut off = tight.clone();
    off.grid.adaptive = false;
    let c = solve_point(&det, 4000.0, &off, None).unwrap();
    assert_eq!(c.accuracy.passes, 1);
    assert!(c.accuracy.c12_err_pf > 0.0);
}

/// Fully depleted points have the same c12 at every bias and from any neighbouring voltage's
/// seed (the point-contact detector gave 1.875 pF at 3300 V and 2.010 pF at 3500-4000 V before).
#[test]
fn depleted_c12_does_not_depend_on_the_bias() {
    let det = detector("detectors/ppc.toml");
    let s = ci_settings();
    let low = solve_point(&det, 2500.0, &s, None).unwrap();
    let seed = low.seed(3500.0 / 2500.0);
    let a = solve_point(&det, 3500.0, &s, Some(&seed)).unwrap();
    let b = solve_point(&det, 4500.0, &s, None).unwrap();
    assert!(a.fully_depleted() && b.fully_depleted());
    assert_eq!(a.c12_pf, b.c12_pf);
    let curve = cv_curve(&det, &[3300.0, 3500.0, 4000.0], &s, |_, _| {}).unwrap();
    for p in &curve.points {
        assert!(p.fully_depleted);
        assert_eq!(p.c12_pf, a.c12_pf, "{} V", p.voltage_v);
    }
}

/// Every shipped detector type at its three biases (undepleted, pinch-off window, depleted) at
/// a 1% tolerance: the actual error against the final grid divided into 4 within 1.5x the
/// tolerance, and wherever that error is more than a quarter of the tolerance (where it decides
/// whether to refine) the estimate at least the actual error or within 1.5x of it. Below that a
/// two-grid difference can cancel by chance (measured: icpc-example at 500 V on these coarse
/// grids, estimate 1.9e-4 against 4.1e-4; at the default tolerance the same point has 8.5e-4
/// against 3.4e-4, reports/accuracy/).
#[test]
fn every_detector_type_within_its_tolerance() {
    let s = ci_settings();
    let mut report = Vec::new();
    let mut bad = Vec::new();
    for case in accuracy_cases() {
        for (bias, kind) in &case.biases {
            let r = accuracy_row(case.detector, *bias, kind, &s, 4).unwrap();
            let line = format!(
                "{} {bias} V ({kind}): c12 {:.4} pF, estimate {:.2e}, actual {:.2e}, {} -> {} nodes",
                case.detector, r.c12_pf, r.estimate_rel, r.actual_rel, r.nodes, r.reference_nodes
            );
            let tol = s.grid.tolerance;
            let ok = if r.actual_rel > 0.25 * tol {
                r.passes(1.5 * tol)
            } else {
                r.actual_rel <= 1.5 * tol
            };
            if !ok {
                bad.push(line.clone());
            }
            report.push(line);
        }
    }
    assert!(
        bad.is_empty(),
        "{}\n\nall:\n{}",
        bad.join("\n"),
        report.join("\n")
    );
}

/// The reference solve of the table reproduces the adaptive solve on its own grid.
#[test]
fn a_point_on_its_own_grid_is_the_same_point() {
    let det = detector("detectors/bege.toml");
    let s = ci_settings();
    let p = solve_point(&det, 2000.0, &s, None).unwrap();
    let q = solve_point_on_grid(&det, 2000.0, &s, p.mesh.grid.clone(), None).unwrap();
    assert!((p.c12_pf / q.c12_pf - 1.0).abs() < 1e-12);
    assert!(q.accuracy.c12_err_pf.is_nan());
}
