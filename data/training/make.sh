#!/usr/bin/env bash
# Regenerates the paper's training data for super-siegfried-k1 (issue: training sets) and prints
# the hashes recorded in data/training/README.md. The training and test sets are not committed
# (28 MB of CSV): this script, the hashes and the generation's saved parts (data/training/parts,
# checkpoint.sh; the run continues from them) are. About 9 h on the 2-core machine with the
# present solver (measured: see the README).
#   paper-60000/rows.csv   60000 samples of spaces/super-siegfried-rz.toml, golden sequence, seed 0
#   train.csv, test.csv    its 80:20 split by index order (0..47999, 48000..59999), as in the paper,
#                          each with its share of the B_Z slice's rows (below)
#   heldout-5000/rows.csv  5000 further samples from offset 100000 (never used for training)
#   calibration-1200/rows.csv  1200 samples from offset 200000: the surrogates' per-point
#                          uncertainty is calibrated on them (hpge-cv calibrate; never trained on)
#   bz-slice-7500/rows.csv 7500 samples of the B_Z slice (spaces/super-siegfried-bz-slice.toml) from
#                          offset 1000000: 6000 join train.csv, 1500 test.csv (README: the slice)
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-data/training}
cargo build --release -q
B=target/release/hpge-cv
S=spaces/super-siegfried-rz.toml
D=detectors/super-siegfried-k1.toml
# A run saved in parts (checkpoint.sh: the generation spans sessions of a machine that keeps no
# files) continues from them; the parts are the rows `generate` wrote, so the result is the same.
for run in paper-60000 bz-slice-7500; do
  if [ ! -e "$OUT/$run" ] && [ -f "data/training/parts/$run/generate.json" ]; then
    bash data/training/checkpoint.sh restore "$run" "$OUT/$run"
  fi
done
$B generate --space $S --detector $D --n 60000 --retry-failed --out "$OUT/paper-60000"
# The held-out and calibration sets are committed (CI checks the shipped models on them): made
# only where $OUT lacks them (delete them, or set OUT to another folder, to make them again).
if [ ! -f "$OUT/heldout.csv" ]; then
  $B generate --space $S --detector $D --n 5000 --offset 100000 --out "$OUT/heldout-5000"
fi
if [ ! -f "$OUT/calibration.csv" ]; then
  $B generate --space $S --detector $D --n 1200 --offset 200000 --out "$OUT/calibration-1200"
fi
$B generate --space spaces/super-siegfried-bz-slice.toml --detector $D --n 7500 --offset 1000000 \
  --retry-failed --out "$OUT/bz-slice-7500"
# Rows in index order (generation appends in completion order).
sorted() { head -n 1 "$1"; tail -n +2 "$1" | sort -t, -k1,1n; }
{
  sorted "$OUT/paper-60000/rows.csv" | awk -F, 'NR == 1 || $1 < 48000'
  sorted "$OUT/bz-slice-7500/rows.csv" | awk -F, 'NR > 1 && $1 < 1006000'
} > "$OUT/train.csv"
{
  sorted "$OUT/paper-60000/rows.csv" | awk -F, 'NR == 1 || $1 >= 48000'
  sorted "$OUT/bz-slice-7500/rows.csv" | awk -F, 'NR > 1 && $1 >= 1006000'
} > "$OUT/test.csv"
[ -f "$OUT/heldout.csv" ] || sorted "$OUT/heldout-5000/rows.csv" > "$OUT/heldout.csv"
[ -f "$OUT/calibration.csv" ] || sorted "$OUT/calibration-1200/rows.csv" > "$OUT/calibration.csv"
# Hash of the content that is deterministic: the columns index to status (so the hash is the same
# for rows written before `c12_err_pF` was added in front of `seconds`, the wall time).
canonical() {
  local s; s=$(head -n 1 "$1" | tr ',' '\n' | grep -nx status | cut -d: -f1)
  tail -n +2 "$1" | cut -d, -f"1-$s" | sha256sum | cut -c1-64
}
for f in train test heldout calibration; do
  echo "$f.csv: $(($(wc -l < "$OUT/$f.csv") - 1)) rows, sha256 (columns index to status) $(canonical "$OUT/$f.csv")"
done
