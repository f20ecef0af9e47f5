//! The 2D field solver on detectors/coax-analytic.toml (a 10 mm slice of an infinitely long coax
//! with reflecting ends) against the closed form: c12 / 10 mm = 2 pi eps / ln(b / r_d).

use hpge_solver::field::Termination;
use hpge_solver::{Detector, FieldSettings, Parameters, solve_point};
use hpge_validation::{LongCoax, repo_path};

fn coax() -> Detector {
    Detector::from_file(
        &repo_path("detectors/coax-analytic.toml"),
        &Parameters::new(),
    )
    .unwrap()
}

/// Acceptance (solver issue): within 0.3% at every voltage 25..2975 V in steps of 50 V with the
/// default settings; the two capacitance formulas agree; the matrix is symmetric.
#[test]
fn c12_matches_closed_form_over_the_whole_curve() {
    let det = coax();
    let s = FieldSettings::default();
    let exact = LongCoax::validation();
    let mut worst: (f64, f64) = (0.0, 0.0);
    for k in 0..60 {
        let v = 25.0 + 50.0 * k as f64;
        let p = solve_point(&det, v, &s, None).unwrap();
        let want = exact.c12_per_mm_pf(v).unwrap();
        let err = (p.c12_pf / 10.0 / want - 1.0).abs();
        if err > worst.1 {
            worst = (v, err);
        }
        let c = &p.capacitance;
        for i in 0..2 {
            for j in 0..2 {
                let (e, q) = (c.energy_pf[i][j], c.charge_pf[i][j]);
                assert!(
                    (e - q).abs() <= 1e-6 * e.abs().max(1e-3),
                    "energy {e} vs charge {q}"
                );
                assert!((c.energy_pf[i][j] - c.energy_pf[j][i]).abs() <= 1e-9 * e.abs().max(1e-3));
            }
            let row: f64 = c.energy_pf[i].iter().sum();
            assert!(row >= -1e-9, "row sum {row} pF must be >= 0");
        }
        assert!(
            p.reports
                .iter()
                .all(|r| r.termination == Termination::ActiveSetStationary)
        );
        assert!(
            p.reports.iter().all(|r| r.residual_v < 1e-6 * v),
            "{:?}",
            p.reports
        );
    }
    assert!(
        worst.1 < 3e-3,
        "worst relative error {:.3e} at {} V",
        worst.1,
        worst.0
    );
}

/// Fully depleted, the log-form conductances make the discrete coax exact.
#[test]
fn fully_depleted_is_exact() {
    let det = coax();
    let p = solve_point(&det, 3600.0, &FieldSettings::default(), None).unwrap();
    let want = 10.0 * LongCoax::validation().c12_per_mm_pf(3600.0).unwrap();
    assert!(p.fully_depleted());
    assert!(
        (p.c12_pf / want - 1.0).abs() < 1e-10,
        "{} vs {want}",
        p.c12_pf
    );
}
