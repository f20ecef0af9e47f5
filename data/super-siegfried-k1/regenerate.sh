#!/usr/bin/env bash
# Regenerates the stand-in Super-Siegfried data set from scratch (about 10 s after the build):
#   1. the truth: the C-V curve of truth-impurity.toml with d_Li = 3 mm from the exact solver,
#   2. raw-like pulser data from it (seeded; decimated traces to keep the files small), with
#      the run's calibration error drawn once (3% on Q_t, R_PG, R1, R2, U_PG: one common
#      factor) and the pulser statistics of 120 pulses per bias,
#   3. the measured curve and covariance from those pulses, with the figures.
set -euo pipefail
cd "$(dirname "$0")/../.."
D=data/super-siegfried-k1
cargo build --release -q
B=target/release/hpge-cv
$B simulate --detector detectors/super-siegfried-k1.toml --impurity "$D/truth-impurity.toml" \
  --d-li 3 --voltages 25:2975:50 --out "$D/truth-cv.csv" --json > "$D/truth-cv.json"
rm -rf "$D/raw"
$B synthesize --curve "$D/truth-cv.csv" --out "$D/raw" --seed 20231001 --pulses 120 --decimate 40 \
  --draw-calibration
$B measure --raw "$D/raw" --out "$D/cv.csv" --plot "$D/figures"
