#!/usr/bin/env bash
# Retrains the shipped surrogate and remakes its figures and held-out figures (issue: surrogate).
#   bash models/train.sh [RECIPE] [SEED]       default: split 0 (the fit's default model)
#   EPOCHS_SCALE=F LOSS_H=H bash models/train.sh ...   the recipe trained F times as long and/or
#     with the robust loss's scale h = H (train --epochs-scale/--loss-h); the files get the
#     suffix -eF and/or -hH, so a variant never replaces the shipped model.
#   TRUNK=W,W,W HEAD=W MEMBERS=N WEIGHT_DECAY=WD bash models/train.sh ...   other layer widths,
#     ensemble size or AdamW's weight decay (train --trunk/--head/--members/--weight-decay);
#     suffixes -tW-W-W, -hdW, -mN, -wdWD.
#   FORCE=1 bash models/train.sh ...   replace a model file of another run (other seed, training
#     or test rows: train --force, calibrate --force); without it train refuses one.
# Needs data/training/{train,test}.csv (bash data/training/make.sh, ~40 min) and the committed
# data/training/{heldout,calibration}.csv. Writes models/super-siegfried-rz-RECIPE.safetensors, its learning
# curves (.curves.csv), the held-out figures (.heldout.json, and as text with the worst samples,
# .heldout.txt) and models/figures/RECIPE/.
set -euo pipefail
cd "$(dirname "$0")/.."
RECIPE=${1:-split}
SEED=${2:-0}
NAME=models/super-siegfried-rz-$RECIPE
VARIANT=()
if [ -n "${EPOCHS_SCALE:-}" ]; then NAME=$NAME-e$EPOCHS_SCALE; VARIANT+=(--epochs-scale "$EPOCHS_SCALE"); fi
if [ -n "${LOSS_H:-}" ]; then NAME=$NAME-h$LOSS_H; VARIANT+=(--loss-h "$LOSS_H"); fi
if [ -n "${TRUNK:-}" ]; then NAME=$NAME-t${TRUNK//,/-}; VARIANT+=(--trunk "$TRUNK"); fi
if [ -n "${HEAD:-}" ]; then NAME=$NAME-hd${HEAD//,/-}; VARIANT+=(--head "$HEAD"); fi
if [ -n "${MEMBERS:-}" ]; then NAME=$NAME-m$MEMBERS; VARIANT+=(--members "$MEMBERS"); fi
if [ -n "${WEIGHT_DECAY:-}" ]; then NAME=$NAME-wd$WEIGHT_DECAY; VARIANT+=(--weight-decay "$WEIGHT_DECAY"); fi
FIGS=models/figures/${NAME#models/super-siegfried-rz-}
if [ ! -f data/training/train.csv ] || [ ! -f data/training/test.csv ]; then
  bash data/training/make.sh
fi
cargo build --release -q
B=target/release/hpge-cv
$B train --data data/training/train.csv --test data/training/test.csv --space spaces/super-siegfried-rz.toml \
  --detector detectors/super-siegfried-k1.toml --recipe "$RECIPE" --seed "$SEED" --out "$NAME.safetensors" \
  "${VARIANT[@]}" --plot "$FIGS" ${FORCE:+--force}
# The per-point uncertainty sigma_s(p, U_B), fitted on rows neither training nor held out, written
# into the model file.
$B calibrate --model "$NAME.safetensors" --data data/training/calibration.csv \
  --out "$NAME.safetensors" ${FORCE:+--force}
$B evaluate --model "$NAME.safetensors" --data data/training/heldout.csv --json > "$NAME.heldout.json"
$B evaluate --model "$NAME.safetensors" --data data/training/heldout.csv --plot "$FIGS" > "$NAME.heldout.txt"
