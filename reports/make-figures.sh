#!/usr/bin/env bash
# Regenerates every figure in reports/figures/ from the shipped detector and impurity files.
# Usage (from the repository root): bash reports/make-figures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/hpge-cv
out=reports/figures
mkdir -p "$out"

# The Super-Siegfried detector in K1 with the manufacturer's impurity model (the default).
$bin detector --detector detectors/super-siegfried-k1.toml \
  --plot "$out/super-siegfried-k1.png" --plot "$out/super-siegfried-k1.svg" > /dev/null
# The paper's example p_zeta,E (p-type near the mantle) with a 3 mm lithium layer.
$bin detector --detector detectors/super-siegfried-k1.toml \
  --impurity detectors/impurities/paper-example-rz.toml --param d_li_mm=3 \
  --plot "$out/super-siegfried-k1-paper-example-rz.png" > /dev/null
# The validation coax and the point-contact example.
$bin detector --detector detectors/coax-analytic.toml --plot "$out/coax-analytic.png" > /dev/null
$bin detector --detector detectors/ppc-example.toml --plot "$out/ppc-example.png" > /dev/null

# The simulated C-V curve of the manufacturer model with d_Li = 1 mm (the paper's section 5) and the
# potential with the undepleted region at 1025 V.
data=reports/data
mkdir -p "$data"
$bin simulate --detector detectors/super-siegfried-k1.toml --d-li 1 --voltages 25:2975:50 --json \
  --out "$data/super-siegfried-k1-manufacturer-cv.csv" \
  --plot "$out/super-siegfried-k1-manufacturer-cv.png" \
  --field 1025 --field-plot "$out/super-siegfried-k1-manufacturer-field-1025V.png" \
  > "$data/super-siegfried-k1-manufacturer-cv.json"
$bin simulate --detector detectors/super-siegfried-k1.toml --d-li 1 --voltages 25:2975:50 \
  --plot "$out/super-siegfried-k1-manufacturer-cv.svg" > /dev/null
# The paper's sensitivity scan: c12 at 25 V for constant densities 1e7..2e11 cm^-3.
$bin sensitivity --detector detectors/super-siegfried-k1.toml --param d_li_mm=1 --voltage 25 \
  --zeta-range 1e7:2e11:18 --out "$data/sensitivity-scan-25V.csv" \
  --plot "$out/super-siegfried-k1-sensitivity-25V.png" > /dev/null
$bin sensitivity --detector detectors/super-siegfried-k1.toml --param d_li_mm=1 --voltage 25 \
  --zeta-range 1e7:2e11:18 --plot "$out/super-siegfried-k1-sensitivity-25V.svg" > /dev/null
echo "figures written to $out/, data to $data/"
