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
echo "figures written to $out/"
