#!/usr/bin/env bash
# Runs the solver, measure and synthesize commands of one hpge-cv binary into a folder, so that
# two builds can be compared file by file (issue 62: "every output unchanged" across a
# restructuring). Wall times (`seconds`) differ between runs; everything else should not.
#
#   bash reports/compare-outputs.sh OLD_BINARY /tmp/cmp/old
#   bash reports/compare-outputs.sh target/release/hpge-cv /tmp/cmp/new
#   diff -r /tmp/cmp/old /tmp/cmp/new        # then compare the JSON files without `seconds`
#
# About 1 min per binary (release builds) on 2 cores. Runs in the repository root; writes only
# under OUT.
set -uo pipefail
[ $# -eq 2 ] || { echo "usage: $0 BINARY OUT" >&2; exit 2; }
B=$(realpath "$1"); O=$(realpath -m "$2")
cd "$(dirname "$0")/.."
mkdir -p "$O"
C=detectors/coax-analytic.toml
$B simulate --detector $C --voltages 1000,3000,4000,3000 --json --out "$O/sim.csv" > "$O/sim.stdout.json" 2> "$O/sim.err"
$B simulate --detector detectors/ppc-example.toml --voltages 300,1200 --json > "$O/sim-ppc.stdout.json" 2> "$O/sim-ppc.err"
$B simulate --detector $C --voltages 1000,3000 > "$O/sim.txt" 2>&1
$B capacitance --detector $C --voltage 4000 --json > "$O/cap.stdout.json" 2>&1
$B capacitance --detector $C --voltage 4000 > "$O/cap.txt" 2>&1
$B field --detector $C --voltage 4000 --phi 0 --z 5 --json --out "$O/field.csv" > "$O/field.stdout.json" 2>&1
$B field --detector $C --voltage 4000 --phi 0 --z 5 --r-range 0:39:5 > "$O/field.txt" 2>&1
$B pulse --detector $C --voltage 4000 --at 20,0,5 --normalise --json --out "$O/pulse.csv" > "$O/pulse.stdout.json" 2>&1
$B pulse --detector $C --voltage 4000 --at 20,0,5 > "$O/pulse.txt" 2>&1
$B sensitivity --detector $C --voltage 1000 --zeta-range 1e9:1e10:3 --json --out "$O/sens.csv" > "$O/sens.stdout.json" 2>&1
$B convergence --detector $C --voltage 2000 --levels 2 --json > "$O/conv.stdout.json" 2>&1
# The measurement: a stand-in folder from the shipped truth curve, then its curve. The paths
# inside the files name OUT, so compare two runs written to the same OUT one after the other.
$B synthesize --curve data/super-siegfried-k1/truth-cv.csv --out "$O/raw" --pulses 20 --decimate 40 > "$O/synth.txt" 2>&1
$B measure --raw "$O/raw" --out "$O/cv.csv" --json > "$O/measure.stdout.json" 2> "$O/measure.err"
for a in "capacitance --voltage -1" "field --voltage 4000 --phi 0 --z 1000" \
  "convergence --voltage 100 --levels 9" "pulse --voltage 4000 --at -1,0,5" \
  "simulate --voltages -5" "pulse --voltage 4000 --at 0,0,5" "field --voltage -3 --phi 0 --z 5"; do
  echo "== $a" >> "$O/errors.txt"
  # shellcheck disable=SC2086
  $B $a --detector $C >> "$O/errors.txt" 2>&1
  echo "exit $?" >> "$O/errors.txt"
done
echo "outputs in $O"
