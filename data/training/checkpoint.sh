#!/usr/bin/env bash
# Keeps a long `hpge-cv generate` run across machines that do not keep files between sessions.
#
#   bash data/training/checkpoint.sh save DIR NAME
#       stores the `ok` rows of the generation folder DIR that data/training/parts/NAME/ does not
#       hold yet as a new part (part-NNN.csv.xz, rows in index order, no header) and copies
#       DIR/generate.json beside the parts (the run's fingerprint and header; and DIR/cpu.json,
#       the run's CPU record, where there is one). Failed rows are
#       left out: `generate --retry-failed` solves them again after a restore.
#   bash data/training/checkpoint.sh restore NAME DIR
#       rebuilds DIR (generate.json and rows.csv from every part) so that the same `generate`
#       command resumes the run where the last saved part ended; refuses an existing DIR.
#   bash data/training/checkpoint.sh check NAME
#       counts the rows and checks that no index appears twice.
#
# The parts are the rows `generate` wrote, byte for byte: a finished set restored from them is
# the set `make.sh` makes (its hashes, data/training/README.md), only sooner.
set -euo pipefail
cd "$(dirname "$0")/../.."
PARTS=${PARTS:-data/training/parts} # another folder for tests
die() { echo "checkpoint.sh: $*" >&2; exit 2; }
indices() { # the indices of every saved part of $1, one per line
  if compgen -G "$PARTS/$1/part-*.csv.xz" > /dev/null; then
    xz -dc "$PARTS/$1"/part-*.csv.xz | cut -d, -f1
  fi
}
case "${1:-}" in
  save)
    [ $# -eq 3 ] || die "usage: save DIR NAME"
    dir=$2; name=$3
    [ -f "$dir/rows.csv" ] && [ -f "$dir/generate.json" ] || die "$dir: no rows.csv and generate.json (not a generate folder)"
    mkdir -p "$PARTS/$name"
    if [ -f "$PARTS/$name/generate.json" ] && ! cmp -s "$dir/generate.json" "$PARTS/$name/generate.json"; then
      die "$dir/generate.json differs from $PARTS/$name/generate.json: rows of another run"
    fi
    cp "$dir/generate.json" "$PARTS/$name/generate.json"
    # The run's CPU record (data/training/cpu.py), where it keeps one.
    if [ -f "$dir/cpu.json" ]; then cp "$dir/cpu.json" "$PARTS/$name/cpu.json"; fi
    names=$(head -n 1 "$dir/rows.csv" | tr ',' '\n')
    status_col=$(grep -nx status <<< "$names" | cut -d: -f1)
    [ -n "$status_col" ] || die "$dir/rows.csv: no status column"
    saved=$(mktemp); new=$(mktemp); trap 'rm -f "$saved" "$new"' EXIT
    indices "$name" | sort -u > "$saved"
    # Whole lines only (a run writing now may have a torn last line), status ok, not saved yet.
    head -n "$(wc -l < "$dir/rows.csv")" "$dir/rows.csv" | tail -n +2 \
      | awk -F, -v s="$status_col" -v n="$(wc -l <<< "$names")" \
          -v saved="$saved" 'BEGIN { while ((getline i < saved) > 0) have[i] = 1 }
                             NF == n && $s == "ok" && !($1 in have)' \
      | sort -t, -k1,1n > "$new"
    count=$(wc -l < "$new")
    if [ "$count" -eq 0 ]; then echo "$name: nothing new to save"; exit 0; fi
    last=$(ls "$PARTS/$name" | grep -c '^part-.*\.csv\.xz$' || true)
    part=$(printf '%s/%s/part-%03d.csv.xz' "$PARTS" "$name" $((last + 1)))
    xz -9 -c "$new" > "$part"
    echo "$name: $count rows saved to $part ($(stat -c %s "$part") bytes); $(($(wc -l < "$saved") + count)) in all"
    ;;
  restore)
    [ $# -eq 3 ] || die "usage: restore NAME DIR"
    name=$2; dir=$3
    [ -f "$PARTS/$name/generate.json" ] || die "$PARTS/$name: no saved run"
    [ ! -e "$dir" ] || die "$dir exists: refusing to overwrite a generation folder"
    mkdir -p "$dir"
    cp "$PARTS/$name/generate.json" "$dir/generate.json"
    if [ -f "$PARTS/$name/cpu.json" ]; then cp "$PARTS/$name/cpu.json" "$dir/cpu.json"; fi
    # generate.json is pretty-printed JSON; its header is a string of names without quotes.
    header=$(sed -n 's/^ *"header": "\([^"]*\)",\{0,1\}$/\1/p' "$dir/generate.json")
    [ -n "$header" ] || die "$dir/generate.json: no \"header\" line"
    { echo "$header"; xz -dc "$PARTS/$name"/part-*.csv.xz | sort -t, -k1,1n; } > "$dir/rows.csv"
    echo "$name: $(($(wc -l < "$dir/rows.csv") - 1)) rows restored to $dir"
    ;;
  check)
    [ $# -eq 2 ] || die "usage: check NAME"
    all=$(mktemp); trap 'rm -f "$all"' EXIT
    indices "$2" | sort > "$all"
    total=$(wc -l < "$all"); twice=$(uniq -d "$all" | wc -l)
    [ "$twice" -eq 0 ] || die "$2: $twice indices appear twice"
    echo "$2: $total rows, every index once"
    ;;
  *) die "usage: save DIR NAME | restore NAME DIR | check NAME" ;;
esac
