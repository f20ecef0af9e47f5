//! The 2D field solver on detectors/planar-pn.toml (an HPGe wafer with a contact on each face and a
//! reflecting mantle: a 1D parallel-plate capacitor) against the closed form
//! c12 = eps A / w(U), w(U) = sqrt(2 eps U / (q N)), and eps A / T beyond U_fd = q N T^2 / (2 eps).
//!
//! Tolerances, measured with the default settings (front spacing h_f = 0.25 mm, 1 mm elsewhere) on
//! a sweep of 400 voltages per window:
//! * partially depleted, the only error is where the free boundary sits: the sub-cell front
//!   (`solver/src/field/front.rs`, second order) leaves |err| <= 0.125 (h_f / w)^2, oscillating with
//!   the front's position in its cell (1.0e-2 at 4.2 V, w = 0.87 mm; 4.1e-3 at 10.6 V; 2.6e-3 at
//!   15 V; 9.4e-4 at 47 V; 1.0e-4 at 421 V). The bound asserted is 0.15 (h_f / w)^2, and the
//!   acceptance bound 0.3% for U >= 15 V (w >= 1.63 mm = 6.5 h_f), where the bound is <= 0.35%;
//! * fully depleted, the discrete problem is a 1D linear one with an exact FV solution: c12 is
//!   eps A / T to rounding;
//! * the solver sees full depletion early, from U_fd (1 - h / T) (h = 1 mm, the spacing next to the
//!   n+ face): there the unconstrained discrete potential no longer exceeds U at the node h below
//!   the n+ face, so the undepleted layer (thinner than about h / 2) has no node and is never
//!   refined; c12 is then eps A / T instead of eps A / w (-5.1% at 509 V). The band is excluded
//!   from the c12 check and asserted as such; `c12_near_full_depletion` records the issue.

use hpge_solver::field::Termination;
use hpge_solver::{Detector, FieldSettings, Parameters, PointResult, solve_point};
use hpge_validation::{PlanarPn, repo_path};

fn planar(params: &Parameters) -> Detector {
    Detector::from_file(&repo_path("detectors/planar-pn.toml"), params).unwrap()
}

/// The solves converged, and the two capacitance formulas (energy and charge) agree.
fn check_solve(p: &PointResult) {
    let c = &p.capacitance;
    for i in 0..2 {
        for j in 0..2 {
            let (e, q) = (c.energy_pf[i][j], c.charge_pf[i][j]);
            assert!(
                (e - q).abs() <= 1e-6 * e.abs().max(1e-3),
                "{} V: energy {e} vs charge {q}",
                p.bias_v
            );
        }
    }
    assert!(
        p.reports
            .iter()
            .all(|r| r.termination == Termination::ActiveSetStationary),
        "{} V: {:?}",
        p.bias_v,
        p.reports
    );
}

/// Voltages of the sweep: 4-20 V in 0.25 V steps (thin layers, w = 0.84-1.88 mm), then 1 V steps
/// through U_fd = 565.5 V to 600 V, then far beyond.
fn sweep() -> Vec<f64> {
    let low = (0..64).map(|k| 4.0 + 0.25 * k as f64);
    let mid = (20..=600).map(f64::from);
    low.chain(mid)
        .chain([700.0, 1000.0, 2000.0, 5000.0])
        .collect()
}

/// Acceptance (solver issue): "a planar p-n / parallel-plate case with a closed form".
#[test]
fn c12_matches_closed_form_from_thin_layer_to_beyond_full_depletion() {
    let det = planar(&Parameters::new());
    let s = FieldSettings::default();
    let exact = PlanarPn::validation();
    let (u_fd, c_fd) = (exact.full_depletion_v(), exact.c12_fully_depleted_pf());
    let h_front = s.grid.front_spacing_mm;
    // Below this the node next to the n+ face must be undepleted (see the module comment).
    let early = u_fd * (1.0 - s.grid.max_spacing_semiconductor_mm / exact.thickness_mm);
    let mut worst = (0.0, 0.0f64);
    let mut worst_scaled = (0.0, 0.0f64);
    for v in sweep() {
        let p = solve_point(&det, v, &s, None).unwrap();
        check_solve(&p);
        let want = exact.c12_pf(v).unwrap();
        let err = p.c12_pf / want - 1.0;
        if v >= u_fd {
            assert!(p.fully_depleted(), "{v} V >= U_fd = {u_fd} V: not depleted");
            assert!(
                err.abs() < 1e-12,
                "{v} V fully depleted: {} vs eps A / T = {want} pF",
                p.c12_pf
            );
        } else if v < early {
            assert!(
                !p.fully_depleted(),
                "{v} V < U_fd (1 - h / T) = {early} V: fully depleted"
            );
            let w = exact.depth_mm(v).unwrap();
            let bound = 0.15 * (h_front / w).powi(2);
            assert!(
                err.abs() <= bound,
                "{v} V (w = {w:.3} mm): c12 {} vs {want} pF, err {err:.3e} > {bound:.3e}",
                p.c12_pf
            );
            if err.abs() / bound > worst_scaled.1 {
                worst_scaled = (v, err.abs() / bound);
            }
            if v >= 15.0 && err.abs() > worst.1 {
                worst = (v, err.abs());
            }
        } else {
            // The band below U_fd where the undepleted layer at the n+ face is thinner than the
            // cell there: no node carries it; the sub-cell front at the contact must find it.
            assert!(!p.fully_depleted(), "{v} V < U_fd: reported fully depleted");
            assert!(
                err.abs() < 3e-3,
                "{v} V: {} vs {want} pF (plate value {c_fd})",
                p.c12_pf
            );
        }
    }
    assert!(
        worst.1 < 3e-3,
        "worst relative error from 15 V: {:.3e} at {} V",
        worst.1,
        worst.0
    );
    assert!(worst_scaled.1 <= 1.0, "{worst_scaled:?}");
}

/// The same with the wafer's parameters changed (T = 6 mm, R = 12 mm): the TOML's expressions and
/// the closed form's constructor agree, and the result does not depend on the aspect ratio.
#[test]
fn parameters_change_the_wafer() {
    let mut params = Parameters::new();
    params.set("thickness_mm", 6.0);
    params.set("radius_mm", 12.0);
    let det = planar(&params);
    let exact = PlanarPn::new(6.0, 12.0);
    let s = FieldSettings::default();
    let u_fd = exact.full_depletion_v();
    for v in [0.3 * u_fd, 0.6 * u_fd, 1.2 * u_fd] {
        let p = solve_point(&det, v, &s, None).unwrap();
        check_solve(&p);
        let want = exact.c12_pf(v).unwrap();
        assert!(
            (p.c12_pf / want - 1.0).abs() < 3e-3,
            "{v} V: {} vs {want} pF",
            p.c12_pf
        );
        assert_eq!(p.fully_depleted(), v > u_fd, "{v} V");
    }
}

/// Just below U_fd the undepleted layer at the n+ face is thinner than about half the 1 mm spacing
/// there, so no node carries it. Before the sub-cell front was anchored at contacts too
/// (`field/front.rs`, `Crossing::at_contact`) the solver reported full depletion from
/// U_fd (1 - h / T) = 508.9 V on with c12 = eps A / T = 17.802 pF, where the closed form gives
/// 18.764 pF at 509 V (-5.1%) and 18.051 pF at 550 V (-1.4%).
#[test]
fn c12_near_full_depletion() {
    let det = planar(&Parameters::new());
    let s = FieldSettings::default();
    let exact = PlanarPn::validation();
    for v in [509.0, 530.0, 550.0, 560.0, 565.0] {
        let p = solve_point(&det, v, &s, None).unwrap();
        let want = exact.c12_pf(v).unwrap();
        assert!(!p.fully_depleted(), "{v} V");
        assert!(
            (p.c12_pf / want - 1.0).abs() < 3e-3,
            "{v} V: {} vs {want} pF",
            p.c12_pf
        );
    }
}
