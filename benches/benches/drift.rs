//! Charge drift and signals (issue 10): the ADL drift velocity of one carrier at one field, the
//! field at one point, and the pulse of the paper's section 9 event (r = 37 mm, phi = 30 deg,
//! z = 35 mm) at 3000 V on super-siegfried-k1 with d_Li = 3 mm, from a potential and weighting
//! potentials computed once (the solve itself is benched in `solver`).

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::drift::{AdlModel, Carrier, DriftModel, DriftSettings, ElectricField};
use hpge_solver::{Detector, FieldSettings, Parameters, pulse, solve_point};
use hpge_validation::repo_path;

pub fn bench(c: &mut Criterion) {
    let mut params = Parameters::new();
    params.set("d_li_mm", 3.0);
    let det = Detector::from_file(&repo_path("detectors/super-siegfried-k1.toml"), &params)
        .expect("shipped detector loads");
    let point = solve_point(&det, 3000.0, &FieldSettings::default(), None).expect("solves");
    let model = AdlModel::default();
    let field = ElectricField::new(&det, &point);
    let settings = DriftSettings::default();
    let at = (37.0, 30f64.to_radians(), 35.0);
    let mut g = c.benchmark_group("drift");
    g.bench_function("adl_velocity_electron", |b| {
        b.iter(|| model.velocity_m_per_s(Carrier::Electron, black_box([1.0e5, 2.0e4, -3.0e4])))
    });
    g.bench_function("adl_velocity_hole", |b| {
        b.iter(|| model.velocity_m_per_s(Carrier::Hole, black_box([1.0e5, 2.0e4, -3.0e4])))
    });
    g.bench_function("field_at", |b| {
        b.iter(|| field.at(black_box(20.0), black_box(0.5), black_box(35.0)))
    });
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    g.bench_function("pulse_section9_3000V", |b| {
        b.iter(|| pulse(&det, &point, &model, black_box(at), &settings).expect("drifts"))
    });
    g.finish();
}
