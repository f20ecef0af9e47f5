#!/usr/bin/env bash
# LEGEND diode records converted by `hpge-cv detector --from-legend`: the ICPC V07646A (a public
# example record of legend-pygeom-hpges's tests, fetched from its source distribution; it has no
# production.impcc, so the converter's default density applies) and the BEGe B00002A
# (detectors/legend/), drawn with their impurity maps, and their simulated full-depletion voltages
# beside the records' characterization (where a record has one). Outputs: reports/legend/.
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN="${HPGE_CV_BIN:-target/release/hpge-cv}"
OUT=reports/legend
TMP="$(mktemp -d)"
python3 -m pip download -q --no-deps --no-binary :all: "legend-pygeom-hpges==0.11.0" -d "$TMP"
tar xzf "$TMP"/legend_pygeom_hpges-0.11.0.tar.gz -C "$TMP"
cp "$TMP"/legend_pygeom_hpges-0.11.0/tests/configs/V07646A.json "$TMP/V07646A.json"
for rec in "$TMP/V07646A.json" detectors/legend/B00002A.json detectors/legend/V00002A.json; do
  name="$(basename "$rec" .json)"
  "$BIN" detector --from-legend "$rec" --out "$TMP/$name.toml" \
    --plot "$OUT/$name.png" --plot "$OUT/$name.svg" > /dev/null 2> "$TMP/$name.log"
  grep "characterization" "$TMP/$name.log" || true
  [ "${PLOTS_ONLY:-0}" = 1 ] && continue
  # U_fd to 100 V (the full-depletion voltage is located between the listed biases) at 1% c12.
  "$BIN" simulate --detector "$TMP/$name.toml" --voltages 500:6000:500 --tolerance 0.01 --json \
    > "$TMP/$name.cv.json"
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(sys.argv[2], 'simulated U_fd', d['depletion_voltage_V'], 'V')" \
    "$TMP/$name.cv.json" "$name"
done
