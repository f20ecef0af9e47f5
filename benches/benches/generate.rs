//! Training-set generation throughput: 16 consecutive samples of the paper's space
//! (spaces/super-siegfried-rz.toml, golden sequence from index 1000) on super-siegfried-k1, one
//! after the other on one core and spread over all cores (rayon), default solver settings. The
//! issue's target: 60000 samples in <= 1 h on the 2-core machine, i.e. >= 16.7 samples/s.

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use hpge_solver::FieldSettings;
use hpge_surrogate::{Generator, ParameterSpace, SequenceKind, Shard};
use hpge_validation::repo_path;
use rayon::prelude::*;

pub fn bench(c: &mut Criterion) {
    let space = ParameterSpace::from_file(&repo_path("spaces/super-siegfried-rz.toml"))
        .expect("shipped space loads");
    let g = Generator::new(
        space,
        &repo_path("detectors/super-siegfried-k1.toml"),
        FieldSettings::default(),
        SequenceKind::Golden,
        0,
        1000,
        16,
        Shard::WHOLE,
    )
    .expect("valid run");
    let mut group = c.benchmark_group("generate");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    group.bench_function("16_samples/one_core", |b| {
        b.iter(|| {
            (1000..1016)
                .map(|i| g.sample(black_box(i)))
                .collect::<Vec<_>>()
        })
    });
    group.bench_function("16_samples/all_cores", |b| {
        b.iter(|| {
            (1000..1016u64)
                .into_par_iter()
                .map(|i| g.sample(black_box(i)))
                .collect::<Vec<_>>()
        })
    });
    group.finish();
}
