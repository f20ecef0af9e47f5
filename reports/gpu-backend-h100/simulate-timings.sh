#!/bin/bash
# Whole-curve timings: the main job's truth curve (60 biases) on CPU fast, CPU sor and wgpu sor.
B=${B:-target/release/hpge-cv}; O=${OUT:-/tmp/simout}; mkdir -p $O/c
V=${V:-25:2975:50}
for tol in 0.002 0.0005; do
  for cfg in "fast cpu" "sor cpu" "sor wgpu"; do
    set -- $cfg
    s=$(date +%s.%N)
    timeout 120 $B simulate --detector detectors/super-siegfried-k1.toml --impurity data/super-siegfried-k1/truth-impurity.toml \
      --d-li 3 --voltages $V --method $1 --backend $2 --tolerance $tol --out $O/c/$1-$2-$tol.csv > /dev/null 2>$O/c/$1-$2-$tol.err || { echo "FAILED $cfg $tol"; tail -3 $O/c/$1-$2-$tol.err; }
    e=$(date +%s.%N)
    echo "tolerance $tol method $1 backend $2: $(python3 -c "print(f'{$e-$s:.2f}')") s wall"
  done
  python3 reports/gpu-backend-h100/compare_curves.py $O/c/fast-cpu-$tol.csv $O/c/sor-cpu-$tol.csv
  python3 reports/gpu-backend-h100/compare_curves.py $O/c/fast-cpu-$tol.csv $O/c/sor-wgpu-$tol.csv
done
rm -rf $O/c
