//! The 2D solver on the long coax with radial rz-model profiles against the 1D high-precision
//! radial reference (validation/src/problems/radial1d/): within 0.5% (solver issue, validation item 2).

use std::path::Path;

use hpge_solver::{Detector, FieldSettings, ImpuritySpec, Parameters, solve_point};
use hpge_validation::{RadialReference, repo_path};

fn coax_with(zeta_knots_cm3: &str) -> Detector {
    let mut det = Detector::from_file(
        &repo_path("detectors/coax-analytic.toml"),
        &Parameters::new(),
    )
    .unwrap();
    let text = format!(
        "model = \"rz\"\nzeta_bot_cm3 = {zeta_knots_cm3}\nzeta_top_cm3 = {zeta_knots_cm3}\n"
    );
    let spec = ImpuritySpec::from_toml_str(&text, Path::new("profile.toml")).unwrap();
    det.set_impurity(&spec, Path::new("profile.toml")).unwrap();
    det
}

fn check(det: &Detector, volts: &[f64], tol: f64) {
    let reference = RadialReference::new(6.0, 37.5);
    let zeta = |r: f64| det.impurity().density_cm3(r, 5.0);
    let settings = FieldSettings::default();
    for &v in volts {
        let exact = reference.solve(&zeta, v).unwrap();
        assert!(exact.fronts_exact, "1D reference not exact at {v} V");
        let p = solve_point(det, v, &settings, None).unwrap();
        let err = p.c12_pf / 10.0 / exact.c12_per_mm_pf - 1.0;
        eprintln!(
            "{v:>6} V: 2D {:.5} pF/mm, 1D {:.5} pF/mm, {err:+.2e}",
            p.c12_pf / 10.0,
            exact.c12_per_mm_pf
        );
        assert!(err.abs() < tol, "{v} V: relative error {err:.3e}");
    }
}

/// n-type bulk turning p-type near the mantle (like the paper's p_zeta,E).
#[test]
fn profile_turning_p_type_near_the_mantle() {
    check(
        &coax_with("[1.2e10, 1.0e10, 0.5e10, -0.4e10]"),
        &[75.0, 275.0, 1025.0, 2025.0],
        5e-3,
    );
}

/// Density falling towards the mantle.
#[test]
fn profile_falling_towards_the_mantle() {
    check(
        &coax_with("[1.3e10, 1.0e10, 0.7e10, 0.4e10]"),
        &[75.0, 525.0, 1525.0, 2525.0],
        5e-3,
    );
}
