#!/usr/bin/env bash
# Regenerates reports/discovery/: the workflow on the shipped data (B_Z start model), and the
# hidden-effect study (exact-solver data sets, one per catalogue entry plus a null case).
# Times on the 2-core machine (exact-solver path, all five catalogue entries): about 20 min for the
# first, about 60-70 min for the second (six data sets).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release
# Both name their committed folders (the defaults are discoveries/...) and replace a run of
# other inputs there (--force; issue 69).
./target/release/hpge-cv discover --out reports/discovery/super-siegfried --seed 0 --force
./target/release/hpge-cv validate discovery --seed 7 --out reports/discovery/hidden --force
# The effect sizes: cargo run --release -p hpge-validation --example identifiability -- \
#   quadratic-z y_quad -0.08 -0.15 0.15   (and: li-slope d_li_slope_mm 2.5)
