#!/usr/bin/env bash
# Rows of the paper-60000 run made on a lent machine with more cores (README: "Rows made on a
# lent 16-core machine"). A row depends only on its index and the run's settings, so sub-ranges
# of the sequence solved elsewhere with the same binary are the run's rows.
#   bash data/training/lent-machine.sh bundle
#       here: the release binary, stripped, with its shared libraries and their loader, packed
#       into .dev/bundle.tar.xz (about 14 MB; .dev/ must be ignored: .git/info/exclude)
#   bash data/training/lent-machine.sh run SECONDS "OFFSET:N OFFSET:N ..."
#       there (the device tool, carry [".dev"]): one `generate --offset OFFSET --n N` per pair,
#       the cores shared among them, stopped after SECONDS; rows.csv of each into $OUT
#   bash data/training/lent-machine.sh merge RUN_FOLDER FILE...
#       here, with the run stopped: appends the rows of FILE... that are `ok`, complete and not
#       yet in RUN_FOLDER/rows.csv (the same header required), then prints the count
# Pick offsets the local run reaches last (it fills its to-do list from both ends of two halves).
set -euo pipefail
cd "$(dirname "$0")/../.."
case "${1:-}" in
  bundle)
    cargo build --release -q -p hpge-cv
    rm -rf /tmp/hpge-bundle && mkdir -p /tmp/hpge-bundle/lib .dev
    cp target/release/hpge-cv /tmp/hpge-bundle/hpge-cv && strip /tmp/hpge-bundle/hpge-cv
    for l in $(ldd target/release/hpge-cv | awk '/=>/ {print $3} /ld-linux/ {print $1}'); do
      cp -L "$l" /tmp/hpge-bundle/lib/
    done
    tar cJf .dev/bundle.tar.xz -C /tmp/hpge-bundle .
    ls -la .dev/bundle.tar.xz
    ;;
  run)
    T=$2; RANGES=$3; START=$(date +%s)
    mkdir -p /tmp/hpgeb
    python3 -c "import tarfile; tarfile.open('.dev/bundle.tar.xz').extractall('/tmp/hpgeb')"
    L=/tmp/hpgeb/lib
    set -- $RANGES
    TH=$(( $(nproc) / $# )); [ "$TH" -ge 1 ] || TH=1
    echo "nproc $(nproc), $# ranges, $TH threads each"
    PIDS=""
    for r in "$@"; do
      o=${r%%:*}; n=${r##*:}
      timeout -s TERM $(( T - ($(date +%s) - START) )) "$L/ld-linux-x86-64.so.2" --library-path "$L" \
        /tmp/hpgeb/hpge-cv generate --space spaces/super-siegfried-rz.toml \
        --detector detectors/super-siegfried-k1.toml --n "$n" --offset "$o" --threads "$TH" \
        --out "/tmp/g$o" > "${OUT:-/tmp}/g$o.log" 2>&1 &
      PIDS="$PIDS $!"
    done
    ( while sleep 60; do for r in "$@"; do o=${r%%:*}; cp "/tmp/g$o/rows.csv" "${OUT:-/tmp}/rows-$o.csv" 2>/dev/null || true; done; done ) &
    CP=$!
    wait $PIDS || true
    kill $CP
    for r in "$@"; do o=${r%%:*}; cp "/tmp/g$o/rows.csv" "${OUT:-/tmp}/rows-$o.csv"; wc -l "${OUT:-/tmp}/rows-$o.csv"; done
    ;;
  merge)
    RUN=$2; shift 2
    if [ -e "$RUN/generate.lock" ] && pgrep -f "generate .*--out $RUN" > /dev/null; then
      echo "stop the run in $RUN first" >&2; exit 2
    fi
    H=$(head -n 1 "$RUN/rows.csv")
    NF=$(echo "$H" | tr ',' '\n' | wc -l)
    ST=$(echo "$H" | tr ',' '\n' | grep -nx status | cut -d: -f1)
    for f in "$@"; do
      [ "$(head -n 1 "$f")" = "$H" ] || { echo "$f: another header" >&2; exit 2; }
    done
    before=$(($(wc -l < "$RUN/rows.csv") - 1))
    tail -q -n +2 "$@" | awk -F, -v nf="$NF" -v st="$ST" 'NF == nf && $st == "ok"' \
      | awk -F, 'NR == FNR { have[$1] = 1; next } !($1 in have) { have[$1] = 1; print }' \
        <(tail -n +2 "$RUN/rows.csv") - >> "$RUN/rows.csv"
    echo "$RUN/rows.csv: $(( $(wc -l < "$RUN/rows.csv") - 1 - before )) rows added, $(( $(wc -l < "$RUN/rows.csv") - 1 )) in all"
    ;;
  *)
    sed -n '2,17p' "$0"; exit 2
    ;;
esac
