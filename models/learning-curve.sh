#!/usr/bin/env bash
# Issue 59, item 3: held-out accuracy against CPU-hours of generation, for rows added uniformly
# and for rows chosen by `generate --where` (active learning), from the 54 000 training rows up.
#
#   bash models/learning-curve.sh ARM K
#
# ARM is `uniform` (data/training/uniform-400000: `generate --n 12000 --offset 400000`),
# `active` (data/training/active-500000: `generate --where` on 120 000 candidates from offset
# 500000, the top 10% solved) or `low-bias` (data/training/low-bias-700000: the same space with
# the bias in 10-110 V, `spaces/super-siegfried-rz-low-bias.toml`; data/training/README.md has
# the commands). The arm's first K rows (`ok`, in index order) join data/training/train.csv (only
# its columns up to `status`: the older rows have no regime columns; each unit coordinate `u_X`
# recomputed from the physical value in the paper's space, so rows of a narrower space such as
# the low-bias one sit where they belong), the recipe RECIPE (default `split-gate` with the
# default model's widths and weight decay) is trained on them with the same test set and seed,
# and one JSON line is appended to models/learning-curves.jsonl. EXTRA (optional): more
# generate folders whose ok rows all join as well (e.g. data/training/bz-low-bias-800000, the
# B_Z slice at 10-110 V), or DIR:N for the first N ok rows of a folder still being generated
# (e.g. data/training/uniform-900000:8000); the line records them and adds their CPU time:
#   arm, k, the arm's CPU seconds for those K rows (CPU_PER_ROW_S of the arm, below, times K),
#   the figures of `evaluate --json` on data/training/heldout-300000.csv and heldout.csv
#   (sigma, q90, q99, coverage, and the pocket / no-pocket split of the former).
# SEED (default 0): the training seed; a seed other than 0 is in the tag and the line.
# K = 0 trains on train.csv alone. A (ARM, K, RECIPE) already in the file is skipped.
# The models go to models/learning-curve/ (not committed: about 0.7 MB each); about 15 min a
# point on the 2-core machine.
set -euo pipefail
cd "$(dirname "$0")/.."
ARM=${1:?usage: learning-curve.sh ARM K}
K=${2:?usage: learning-curve.sh ARM K}
RECIPE=${RECIPE:-split-gate}
SEED=${SEED:-0}
EXTRA=${EXTRA:-}
case "$ARM" in
  uniform) DIR=data/training/uniform-400000 ;;
  active) DIR=data/training/active-500000 ;;
  low-bias) DIR=data/training/low-bias-700000 ;;
  *) echo "learning-curve.sh: ARM must be uniform, active or low-bias, not '$ARM'" >&2; exit 2 ;;
esac
for E in $EXTRA; do
  D=${E%%:*}
  [ -f "$D/rows.csv" ] && [ -f "$D/cpu.json" ] || { echo "learning-curve.sh: EXTRA folder '$D' has no rows.csv and cpu.json" >&2; exit 2; }
  if [ "$D" != "$E" ] && ! [[ "${E#*:}" =~ ^[0-9]+$ ]]; then echo "learning-curve.sh: EXTRA '$E': N in DIR:N must be a count of rows" >&2; exit 2; fi
done
TAG=$ARM-$K
for E in $EXTRA; do
  D=${E%%:*}
  if [ "$D" = "$E" ]; then TAG=$TAG+$(basename "$D"); else TAG=$TAG+$(basename "$D")-first${E#*:}; fi
done
[ "$SEED" = 0 ] || TAG=$TAG-seed$SEED
[[ "$K" =~ ^[0-9]+$ ]] || { echo "learning-curve.sh: K must be a count of rows, not '$K'" >&2; exit 2; }
OUT=models/learning-curves.jsonl
if [ -f "$OUT" ] && grep -q "\"tag\": \"$TAG\", \"recipe\": \"$RECIPE\"" "$OUT"; then
  echo "learning-curve.sh: $TAG $RECIPE is in $OUT already"; exit 0
fi
if [ -z "$EXTRA" ] && [ "$SEED" = 0 ] && [ -f "$OUT" ] && grep -q "\"arm\": \"$ARM\", \"k\": $K, \"recipe\": \"$RECIPE\"" "$OUT"; then
  echo "learning-curve.sh: $ARM $K $RECIPE is in $OUT already"; exit 0
fi
[ -f data/training/train.csv ] || bash data/training/make.sh
cargo build --release -q
B=target/release/hpge-cv
mkdir -p models/learning-curve
SET=models/learning-curve/train-$TAG.csv
python3 - "$DIR/rows.csv" "$K" "$SET" $EXTRA <<'EOF'
import csv, re, sys
rows_file, k, out, extra = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4:]
# The paper's space: every dimension uniform on its range (spaces/super-siegfried-rz.toml).
ranges, name = {}, None
for line in open("spaces/super-siegfried-rz.toml"):
    m = re.match(r'name = "(.*)"', line.strip())
    if m:
        name = m.group(1)
    m = re.match(r"range = \[(.*), (.*)\]", line.strip())
    if m:
        ranges[name] = (float(m.group(1)), float(m.group(2)))
with open("data/training/train.csv") as f:
    base = list(csv.reader(f))
header = base[0]
def ok_rows(path):
    with open(path) as f:
        ok = [row for row in csv.DictReader(f) if row["status"] == "ok"]
    return sorted(ok, key=lambda row: int(row["index"]))
def line(row):
    for h in header:
        if h.startswith("u_"):
            lo, hi = ranges[h[2:]]
            u = (float(row[h[2:]]) - lo) / (hi - lo)
            if abs(u - float(row[h])) > 1e-12:  # a row of another space (low-bias)
                row[h] = repr(u)
    return [row[h] for h in header]
added = []
if k > 0:
    ok = ok_rows(rows_file)
    if len(ok) < k:
        sys.exit(f"learning-curve.sh: {rows_file} has {len(ok)} ok rows, fewer than K = {k}")
    added = [line(row) for row in ok[:k]]
for e in extra:
    folder, _, n = e.partition(":")
    ok = ok_rows(folder + "/rows.csv")
    if n:
        if len(ok) < int(n):
            sys.exit(f"learning-curve.sh: {folder}/rows.csv has {len(ok)} ok rows, fewer than {n}")
        ok = ok[: int(n)]
    added += [line(row) for row in ok]
with open(out, "w", newline="") as f:
    w = csv.writer(f, lineterminator="\n")
    w.writerows(base)
    w.writerows(added)
EOF
MODEL=models/learning-curve/$RECIPE-$TAG.safetensors
SHIPPED=models/super-siegfried-rz-$RECIPE-t256-256-256-hd128-wd0.01.safetensors
if [ "$K" -eq 0 ] && [ -z "$EXTRA" ] && [ "$SEED" = 0 ] && [ -f "$SHIPPED" ] && cmp -s "$SET" data/training/train.csv; then
  # The 54 000 rows alone with the same recipe, seed and test set: the committed model is this
  # point (models/train.sh trained it with the same arguments).
  cp "$SHIPPED" "$MODEL"
else
  $B train --data "$SET" --test data/training/test.csv --space spaces/super-siegfried-rz.toml \
    --detector detectors/super-siegfried-k1.toml --recipe "$RECIPE" --seed "$SEED" --out "$MODEL" \
    --trunk 256,256,256 --head 128 --weight-decay 0.01 --force
  $B calibrate --model "$MODEL" --data data/training/calibration.csv --out "$MODEL" --force
fi
$B evaluate --model "$MODEL" --data data/training/heldout-300000.csv --json > "${MODEL%.safetensors}.h300000.json"
$B evaluate --model "$MODEL" --data data/training/heldout.csv --json > "${MODEL%.safetensors}.heldout.json"
CPU=0
if [ "$K" -gt 0 ]; then CPU=$(python3 -c "import json; print(json.load(open('$DIR/cpu.json'))['cpu_per_row_s'] * $K)"); fi
for E in $EXTRA; do
  D=${E%%:*}
  N=""; [ "$D" = "$E" ] || N=${E#*:}
  CPU=$(python3 -c "import csv, json; d = json.load(open('$D/cpu.json')); n = sum(1 for r in csv.DictReader(open('$D/rows.csv')) if r['status'] == 'ok'); n = min(n, int('$N')) if '$N' else n; print($CPU + d['cpu_per_row_s'] * n)")
done
python3 - "$ARM" "$K" "$RECIPE" "$CPU" "${MODEL%.safetensors}" "$TAG" "$EXTRA" "$SEED" >> "$OUT" <<'EOF'
import json, sys
arm, k, recipe, cpu, stem = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4]), sys.argv[5]
tag, extra, seed = sys.argv[6], sys.argv[7], int(sys.argv[8])
def figs(f):
    d = json.load(open(f))
    out = {key: d[key] for key in ("n", "rel_sigma", "abs_rel_q90", "abs_rel_q99", "coverage_2sigma")}
    for r in d.get("regimes") or []:
        out[r["group"]] = {key: r[key] for key in ("n", "rel_sigma", "abs_rel_q90", "abs_rel_q99")}
    return out
head = {"arm": arm, "k": k, "recipe": recipe}
if extra or seed:
    head = {"tag": tag, "recipe": recipe, "arm": arm, "k": k, "extra": extra.split()}
if seed:
    head["seed"] = seed
print(json.dumps({**head, "cpu_s": cpu,
                  "heldout_300000": figs(stem + ".h300000.json"),
                  "heldout": figs(stem + ".heldout.json"),
                  "program_version": json.load(open(stem + ".h300000.json")).get("program_version")}))
EOF
tail -n 1 "$OUT"
