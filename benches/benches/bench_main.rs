//! All criterion benches: `cargo bench -p hpge-benches [-- FILTER]`.

use criterion::{criterion_group, criterion_main};

mod impurity;
mod solver;

criterion_group!(benches, impurity::bench, solver::bench);
criterion_main!(benches);
