//! The field solver on validation's closed-form problems (`hpge_validation::problems`), so that
//! its speed is tracked where the answer is known: the planar p-n wafer
//! (`detectors/planar-pn.toml`, [`PlanarPn`]) and the long coax slice
//! (`detectors/coax-analytic.toml`, [`LongCoax`]), each at the default settings (the size of
//! their tests in `validation/tests/planar_closed_form.rs` and `coax_2d.rs`), both potential
//! methods: one point partially depleted, one fully depleted, and the coax's 60-point curve
//! (25..2975 V, step 50, the test's sweep). Before timing, each point is checked once against
//! the closed form (the tests' 0.3% acceptance bound), so a bench never times a wrong answer.

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::{Detector, FieldSettings, Method, Parameters, cv_curve, solve_point};
use hpge_validation::{LongCoax, PlanarPn, repo_path};

/// The tests' acceptance bound on |c12 / closed form - 1|.
const TOLERANCE: f64 = 3e-3;

fn shipped(file: &str) -> Detector {
    Detector::from_file(&repo_path(file), &Parameters::new()).expect("shipped detector loads")
}

/// Panics unless `got` is within [`TOLERANCE`] of `want`.
fn check(what: &str, got_pf: f64, want_pf: f64) {
    let err = (got_pf / want_pf - 1.0).abs();
    assert!(
        err < TOLERANCE,
        "{what}: c12 {got_pf} pF against the closed form's {want_pf} pF (relative error {err:.2e})"
    );
}

pub fn bench(c: &mut Criterion) {
    let planar = shipped("detectors/planar-pn.toml");
    let coax = shipped("detectors/coax-analytic.toml");
    let (wafer, slice) = (PlanarPn::validation(), LongCoax::validation());
    let volts: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
    let mut g = c.benchmark_group("closed_form");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for method in [Method::Fast, Method::Sor] {
        let s = FieldSettings {
            method,
            ..FieldSettings::default()
        };
        let m = method.as_str();
        // Planar: partially depleted (w = 5.9 mm of T = 10 mm) and beyond U_fd = 565.5 V.
        for v in [200.0, 1000.0] {
            let p = solve_point(&planar, v, &s, None).expect("solves");
            check(
                &format!("planar {v} V ({m})"),
                p.c12_pf,
                wafer.c12_pf(v).expect("closed form"),
            );
            g.bench_function(format!("planar_pn/point_{v}V/{m}"), |b| {
                b.iter(|| solve_point(&planar, black_box(v), &s, None).expect("solves"))
            });
        }
        // Coax (a 10 mm slice): the front at mid-radius, and fully depleted (U_fd ~ 3.5 kV).
        for v in [1025.0, 3600.0] {
            let p = solve_point(&coax, v, &s, None).expect("solves");
            check(
                &format!("coax {v} V ({m})"),
                p.c12_pf / 10.0,
                slice.c12_per_mm_pf(v).expect("closed form"),
            );
            g.bench_function(format!("coax/point_{v}V/{m}"), |b| {
                b.iter(|| solve_point(&coax, black_box(v), &s, None).expect("solves"))
            });
        }
        g.bench_function(format!("coax/curve_60/{m}"), |b| {
            b.iter(|| cv_curve(&coax, black_box(&volts), &s, |_, _| {}).expect("solves"))
        });
    }
    g.finish();
}
