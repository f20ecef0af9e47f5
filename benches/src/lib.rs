//! Criterion benches of hpge-cv live in `benches/bench_main.rs` (one module per area). Run them
//! with `cargo bench -p hpge-benches`; results land in `target/criterion/`.
//!
//! The crate also keeps research code that is not part of the product, with its measurements as
//! examples: the smoothed-aggregation multigrid ([`amg`], `--example amg_timing`) and the SOR
//! over-relaxation scan (`--example omega_scan`).

#![warn(missing_docs)]

pub mod amg;
