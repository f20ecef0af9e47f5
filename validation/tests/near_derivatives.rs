//! Forward differences on the base point's grids (`hpge_solver::field::cv_curves_near`) against
//! the closed form of the long coax (detectors/coax-analytic.toml): dc'/dN and dc'/db, with c'
//! = 2 pi eps / ln(b / r_d) and r_d from V = (q N / 2 eps)[(b^2 - r_d^2)/2 - r_d^2 ln(b / r_d)].
//! The closed form's derivatives are central differences of the closed form itself (smooth,
//! exact to ~1e-8 relative at these steps).

use std::path::Path;

use hpge_solver::field::{Continuation, cv_curves_near};
use hpge_solver::{Detector, FieldSettings, Parameters};
use hpge_validation::problems::stand_in::{stand_in_solver, stand_in_truth};
use hpge_validation::{LongCoax, repo_path};

/// The coax file with the outer radius and the density replaced.
fn coax(b_mm: f64, n_cm3: f64) -> Detector {
    let text = std::fs::read_to_string(repo_path("detectors/coax-analytic.toml")).unwrap();
    let text = text
        .replace("r_mm = [6.0, 37.5]", &format!("r_mm = [6.0, {b_mm:e}]"))
        .replace("r_mm = 37.5,", &format!("r_mm = {b_mm:e},"))
        .replace("zeta_cm3 = 1.0e10", &format!("zeta_cm3 = {n_cm3:e}"));
    Detector::from_toml_str(
        &text,
        Path::new("coax-analytic (modified)"),
        &Parameters::new(),
    )
    .unwrap()
}

/// dc'/dp of the closed form (pF/mm per unit of p) by a central difference.
fn closed_form_derivative(v: f64, step: f64, set: impl Fn(&mut LongCoax, f64)) -> f64 {
    let at = |d: f64| {
        let mut c = LongCoax::validation();
        set(&mut c, d);
        c.c12_per_mm_pf(v).unwrap()
    };
    (at(step) - at(-step)) / (2.0 * step)
}

#[test]
fn near_differences_follow_the_closed_form_in_density_and_radius() {
    let volts = [400.0, 1000.0, 1800.0, 2600.0];
    let s = FieldSettings::default();
    let base = coax(37.5, 1.0e10);
    let (hb, hn) = (0.05, 1.0e8);
    let near = [
        coax(37.5 + hb, 1.0e10),
        coax(37.5, 1.0e10 + hn),
        coax(37.5, 1.0e10),
    ];
    let nc = cv_curves_near(&base, &near, &volts, &s, Continuation::Seeded).unwrap();
    assert_eq!(
        nc.regridded, 0,
        "every nearby point on a deformed base grid"
    );
    for (k, p) in nc.base.points.iter().enumerate() {
        let v = p.voltage_v;
        // The same detector on its own grid: the base curve exactly.
        assert_eq!(nc.near_pf[2][k], p.c12_pf, "{v} V");
        // Per mm of the 10 mm slice.
        let d_b = (nc.near_pf[0][k] - p.c12_pf) / hb / 10.0;
        let d_n = (nc.near_pf[1][k] - p.c12_pf) / hn / 10.0;
        let want_b = closed_form_derivative(v, 1e-4, |c, d| c.b_mm += d);
        let want_n = closed_form_derivative(v, 1e5, |c, d| c.n_cm3 += d);
        // Forward differences carry O(h) of the second derivative, and the grid's error in c'
        // (within 0.3%, tests/coax_2d.rs) changes as the nodes move relative to the depletion
        // front: measured -1.1% to +1.4% for N and -8.1% to +2.3% for b (the b step moves every
        // node between the contacts); two adaptive solves give the same numbers here (the
        // coax's grid keeps its structure). Bounds: 3% for N, 10% for b.
        for (name, got, want, bound) in [("b", d_b, want_b, 0.10), ("N", d_n, want_n, 0.03)] {
            assert!(
                (got / want - 1.0).abs() < bound,
                "{v} V: dc'/d{name} {got:.6e} vs closed form {want:.6e}"
            );
        }
    }
}

/// Super-Siegfried at the stand-in truth (data/super-siegfried-k1/README.md), a step in y4_bot
/// (1% of its range, `discover`'s forward difference): on the base grids the difference is
/// smooth, the step and half the step give the same derivative; two adaptive solves at 1825 V
/// end on different grids (measured: -1.44 pF per unit against -0.249 on the base grid,
/// `validation/examples/fd_near.rs`).
#[test]
fn near_differences_in_an_impurity_knot_are_smooth() {
    let ex = stand_in_solver().unwrap();
    let x: [f64; 9] = stand_in_truth(&ex).unwrap().try_into().unwrap();
    let h = 0.02;
    let step = |d: f64| {
        let mut y = x;
        y[4] += d;
        ex.detector(&y).unwrap()
    };
    let volts = [1225.0, 1825.0, 2425.0];
    let nc = cv_curves_near(
        &step(0.0),
        &[step(h), step(0.5 * h)],
        &volts,
        &ex.settings,
        Continuation::Cold,
    )
    .unwrap();
    assert_eq!(nc.regridded, 0);
    for (k, p) in nc.base.points.iter().enumerate() {
        let d_h = (nc.near_pf[0][k] - p.c12_pf) / h;
        let d_half = (nc.near_pf[1][k] - p.c12_pf) / (0.5 * h);
        assert!(d_h < 0.0, "{} V: {d_h}", p.voltage_v);
        assert!(
            (d_h / d_half - 1.0).abs() < 0.05,
            "{} V: {d_h} (h) vs {d_half} (h/2) pF per unit",
            p.voltage_v
        );
    }
}
