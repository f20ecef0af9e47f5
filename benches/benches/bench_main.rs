//! All criterion benches: `cargo bench -p hpge-benches [-- FILTER]`.

use criterion::{criterion_group, criterion_main};

mod depletion;
mod drift;
mod generate;
mod gpu;
mod impurity;
mod inference;
mod problems;
mod solver;
mod surrogate;

criterion_group!(
    benches,
    impurity::bench,
    solver::bench,
    depletion::bench,
    problems::bench,
    gpu::bench,
    generate::bench,
    surrogate::bench,
    inference::bench,
    drift::bench
);
criterion_main!(benches);
