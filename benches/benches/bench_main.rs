//! All criterion benches: `cargo bench -p hpge-benches [-- FILTER]`.

use criterion::{criterion_group, criterion_main};

mod impurity;

criterion_group!(benches, impurity::bench);
criterion_main!(benches);
