//! Field solver: one c12 point and the 60-point C-V curve (25..2975 V, step 50) of
//! super-siegfried-k1 with the manufacturer impurity model and d_Li = 1 mm, default settings
//! (adaptive to the default tolerance, 0.2%), both potential methods. The target for `fast`: the
//! curve in <= 3 s on the 2-core machine (issue 18). The curve with one forward-difference step
//! on its grids (`field::cv_curves_near`) against two adaptive curves. Then every shipped
//! detector type at its three biases of the accuracy table (undepleted, pinch-off window,
//! depleted; `hpge_validation::accuracy_cases`) at the default tolerance. Last, the exact-solver
//! check's solves: draws of a two-mode posterior on the mode's grids (20 voltages, 4 draws
//! around the stand-in's truth and 4 around its mirror, bottom and top swapped), each seeded
//! from the mode's potential against along a nearest-neighbour chain (`field::SeedChain`;
//! the same c12 bit for bit, `validation/tests/near_chain.rs`).

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::field::{
    Continuation, NearSeeding, SeedChain, cv_curves_near, cv_curves_near_each,
};
use hpge_solver::{Detector, FieldSettings, Method, Parameters, cv_curve, solve_point};
use hpge_validation::{accuracy_cases, repo_path};

pub fn bench(c: &mut Criterion) {
    let det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )
    .expect("shipped detector loads");
    let volts: Vec<f64> = (0..60).map(|k| 25.0 + 50.0 * k as f64).collect();
    let mut g = c.benchmark_group("super_siegfried");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for method in [Method::Fast, Method::Sor] {
        let s = FieldSettings {
            method,
            ..FieldSettings::default()
        };
        for v in [25.0, 1025.0, 2975.0] {
            g.bench_function(format!("point_{}V/{}", v, method.as_str()), |b| {
                b.iter(|| solve_point(&det, black_box(v), &s, None).expect("solves"))
            });
        }
        g.bench_function(format!("curve_60/{}", method.as_str()), |b| {
            b.iter(|| cv_curve(&det, black_box(&volts), &s, |_, _| {}).expect("solves"))
        });
    }
    // A forward-difference step of `discover`'s exact quick fits: the curve and the curve at
    // d_Li + 0.048 mm (1% of the paper's prior range) on its grids (`field::cv_curves_near`),
    // against the two curves solved adaptively.
    let mut stepped = Parameters::new();
    stepped.set("d_li_mm", 1.048);
    let near = Detector::from_file(&repo_path("detectors/super-siegfried-k1.toml"), &stepped)
        .expect("shipped detector loads");
    let s = FieldSettings::default();
    g.bench_function("curve_60_and_step/near", |b| {
        b.iter(|| {
            cv_curves_near(
                &det,
                std::slice::from_ref(&near),
                black_box(&volts),
                &s,
                Continuation::Seeded,
            )
            .expect("solves")
        })
    });
    g.bench_function("curve_60_and_step/adaptive", |b| {
        b.iter(|| {
            let c0 = cv_curve(&det, black_box(&volts), &s, |_, _| {}).expect("solves");
            let c1 = cv_curve(&near, black_box(&volts), &s, |_, _| {}).expect("solves");
            (c0, c1)
        })
    });
    g.finish();
    let mut g = c.benchmark_group("detector_types");
    g.sample_size(10).measurement_time(Duration::from_secs(30));
    let s = FieldSettings::default();
    for case in accuracy_cases() {
        let det = Detector::from_file(&repo_path(case.detector), &Parameters::new())
            .expect("shipped detector loads");
        let name = case
            .detector
            .trim_start_matches("detectors/")
            .trim_end_matches(".toml");
        let volts: Vec<f64> = case.biases.iter().map(|(v, _)| *v).collect();
        g.bench_function(format!("curve_3/{name}"), |b| {
            b.iter(|| cv_curve(&det, black_box(&volts), &s, |_, _| {}).expect("solves"))
        });
    }
    g.finish();
    check_draws(c);
}

/// The exact check's draws of a two-mode posterior, seeded from the mode or along a chain.
fn check_draws(c: &mut Criterion) {
    use hpge_validation::problems::stand_in::{
        input_widths, stand_in_solver, stand_in_truth, two_mode_draws,
    };
    let ex = stand_in_solver().expect("the stand-in's exact solver sets up");
    let truth: [f64; 9] = stand_in_truth(&ex)
        .expect("the stand-in's truth reads")
        .try_into()
        .expect("nine inputs");
    let xs = two_mode_draws(&truth, 4);
    let det = ex.detector(&truth).expect("detector");
    let near: Vec<_> = xs
        .iter()
        .map(|x| ex.detector(x).expect("detector"))
        .collect();
    let chain = SeedChain::nearest_neighbour(&truth, &xs, &input_widths(&ex));
    let volts: Vec<f64> = (0..20).map(|k| 25.0 + 150.0 * k as f64).collect();
    let mut g = c.benchmark_group("exact_check_draws");
    g.sample_size(10).measurement_time(Duration::from_secs(40));
    for (name, seeding) in [("from_mode", NearSeeding::Base), ("chain", chain.seeding())] {
        g.bench_function(format!("8_draws_20V/{name}"), |b| {
            b.iter(|| {
                cv_curves_near_each(
                    &det,
                    &near,
                    black_box(&volts),
                    &ex.settings,
                    (Continuation::Seeded, seeding),
                    |_, _| {},
                )
                .expect("solves")
            })
        });
    }
    g.finish();
}
