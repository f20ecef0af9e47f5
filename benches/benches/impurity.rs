//! Impurity-model evaluation: the field solver evaluates the density at every grid node for
//! every parameter set, so this must stay in the tens of nanoseconds per point.

use std::hint::black_box;

use criterion::Criterion;
use hpge_solver::impurity::LogTransform;
use hpge_solver::{Detector, Parameters};
use hpge_validation::repo_path;

pub fn bench(c: &mut Criterion) {
    let t = LogTransform::default();
    c.bench_function("transform/zeta_cm3_of_y", |b| {
        b.iter(|| t.zeta_cm3_of_y(black_box(0.7062704)))
    });
    c.bench_function("transform/y_of_zeta_cm3", |b| {
        b.iter(|| t.y_of_zeta_cm3(black_box(1.3e10)))
    });

    let mut det = Detector::from_file(
        &repo_path("detectors/super-siegfried-k1.toml"),
        &Parameters::new(),
    )
    .expect("shipped detector loads");
    det.set_impurity_file(&repo_path("detectors/impurities/paper-example-rz.toml"))
        .expect("shipped impurity file loads");
    // A 100 x 100 grid over the crystal.
    let pts: Vec<(f64, f64)> = (0..100)
        .flat_map(|i| (0..100).map(move |j| (5.0 + 32.5 * i as f64 / 99.0, 70.0 * j as f64 / 99.0)))
        .collect();
    c.bench_function("rz_model/density_10k_points", |b| {
        b.iter(|| {
            let m = det.impurity();
            pts.iter().map(|&(r, z)| m.density_cm3(r, z)).sum::<f64>()
        })
    });
    c.bench_function("detector/classify_10k_points", |b| {
        b.iter(|| {
            pts.iter()
                .filter(|&&(r, z)| {
                    matches!(
                        det.classify(r, z),
                        hpge_solver::detector::Region::Semiconductor
                    )
                })
                .count()
        })
    });
}
