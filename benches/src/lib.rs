//! Criterion benches of hpge-cv live in `benches/bench_main.rs` (one module per area). Run them
//! with `cargo bench -p hpge-benches`; results land in `target/criterion/`.
