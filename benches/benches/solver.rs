//! Field solver: one c12 point and the 60-point C-V curve (25..2975 V, step 50) of
//! super-siegfried-k1 with the manufacturer impurity model and d_Li = 1 mm, default
//! (converged) settings, both potential methods. The target for `fast`: the curve in
//! <= 3 s on the 2-core machine.

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::{Detector, FieldSettings, Method, Parameters, cv_curve, solve_point};
use hpge_validation::repo_path;

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
    g.finish();
}
