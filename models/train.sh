#!/usr/bin/env bash
# Retrains the shipped surrogate and remakes its figures and held-out figures (issue: surrogate).
#   bash models/train.sh [RECIPE] [SEED]       default: split 0 (the fit's default model)
# Needs data/training/{train,test}.csv (bash data/training/make.sh, ~40 min) and the committed
# data/training/{heldout,calibration}.csv. Writes models/super-siegfried-rz-RECIPE.safetensors, its learning
# curves (.curves.csv), the held-out figures (.heldout.json) and models/figures/RECIPE/.
set -euo pipefail
cd "$(dirname "$0")/.."
RECIPE=${1:-split}
SEED=${2:-0}
NAME=models/super-siegfried-rz-$RECIPE
if [ ! -f data/training/train.csv ] || [ ! -f data/training/test.csv ]; then
  bash data/training/make.sh
fi
cargo build --release -q
B=target/release/hpge-cv
$B train --data data/training/train.csv --test data/training/test.csv --space spaces/super-siegfried-rz.toml \
  --detector detectors/super-siegfried-k1.toml --recipe "$RECIPE" --seed "$SEED" --out "$NAME.safetensors" \
  --plot "models/figures/$RECIPE"
# The per-point uncertainty sigma_s(p, U_B), fitted on rows neither training nor held out.
$B calibrate --model "$NAME.safetensors" --data data/training/calibration.csv
$B evaluate --model "$NAME.safetensors" --data data/training/heldout.csv --json > "$NAME.heldout.json"
$B evaluate --model "$NAME.safetensors" --data data/training/heldout.csv --plot "models/figures/$RECIPE"
