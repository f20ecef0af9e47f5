#!/usr/bin/env bash
# Held-out accuracy against the number of training rows and the recipe, on the regenerated
# training rows saved so far (reports/surrogate.md, "Pinch-off steps"). Every model is
# evaluated on the committed data/training/heldout.csv after `calibrate` on calibration.csv.
#   bash reports/surrogate-scaling.sh [OUT]      (OUT: a folder, default /tmp/surrogate-scaling)
# The rows: the paper-60000 parts (data/training/parts/), restored. Training sets are index
# ranges of the run: 0-1999 (2 000 rows), 0-3999 (4 000), 0-4803 and 30000-32914 (7 719); the
# test set (learning curves only) is 32915-34849. Prints one line per model and writes
# OUT/results.txt; about 1 min per network at 150 epochs on 2 cores, 25 min in all.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-/tmp/surrogate-scaling}
mkdir -p "$OUT"
cargo build --release -q
B=$PWD/target/release/hpge-cv
if [ ! -f "$OUT/rows/rows.csv" ]; then
  bash data/training/checkpoint.sh restore paper-60000 "$OUT/rows"
fi
ROWS=$OUT/rows/rows.csv
subset() { # NAME AWK-CONDITION: the rows of ROWS whose index satisfies the condition, in index order
  { head -1 "$ROWS"; tail -n +2 "$ROWS" | awk -F, "$2" | sort -t, -k1,1n; } > "$OUT/$1.csv"
}
subset train-2000 '$1 < 2000'
subset train-4000 '$1 < 4000'
subset train-7719 '$1 <= 4803 || ($1 >= 30000 && $1 <= 32914)'
subset test '$1 >= 32915 && $1 <= 34849'
for n in 2000 4000 7719; do
  [ "$(($(wc -l < "$OUT/train-$n.csv") - 1))" -eq "$n" ] || {
    echo "surrogate-scaling.sh: train-$n.csv has not $n rows (not enough rows saved yet?)" >&2
    exit 2
  }
done
one() { # TRAIN RECIPE TAG [extra train options]: the model is OUT/TRAIN-RECIPE[-TAG]
  local train=$1 recipe=$2 tag=$3
  shift 3
  local name=$train-$recipe${tag:+-$tag}
  $B train --data "$OUT/$train.csv" --test "$OUT/test.csv" --space spaces/super-siegfried-rz.toml \
    --recipe "$recipe" --out "$OUT/$name.safetensors" "$@" 2> "$OUT/$name.log"
  $B calibrate --model "$OUT/$name.safetensors" --data data/training/calibration.csv >> "$OUT/$name.log" 2>&1
  $B evaluate --model "$OUT/$name.safetensors" --data data/training/heldout.csv --json > "$OUT/$name.json"
  python3 - "$OUT/$name.json" "$name" <<'EOF' | tee -a "$OUT/results.txt"
import json, sys
d = json.load(open(sys.argv[1]))
print(f"{sys.argv[2]:34s} sigma {100 * d['rel_sigma']:.2f}%  q90 {100 * d['abs_rel_q90']:.1f}%  "
      f"q99 {100 * d['abs_rel_q99']:.1f}%  max {100 * d['abs_rel_max']:.0f}%  "
      f"coverage_2sigma {d['coverage_2sigma']:.3f}")
EOF
}
: > "$OUT/results.txt"
for n in 2000 4000 7719; do
  one train-$n split ""
  one train-$n split-steps ""
done
one train-7719 split e4 --epochs-scale 4
one train-7719 split e4-h25 --epochs-scale 4 --loss-h 25
one train-7719 split-steps e4 --epochs-scale 4
one train-7719 split-steps-ensemble ""
