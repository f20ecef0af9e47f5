#!/usr/bin/env bash
# Regenerates reports/discovery/: the workflow on the shipped data (B_Z start model), and the
# hidden-effect study (exact-solver data sets, one per catalogue entry plus a null case).
# Times on the 2-core machine: about 10 min for the first, about 40 min for the second.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release
./target/release/hpge-cv discover --out reports/discovery/super-siegfried --seed 0
./target/release/hpge-cv validate discovery --seed 7 --out reports/discovery/hidden || true
