#!/usr/bin/env bash
# Runs the shell blocks of documentation pages as printed (issue 61): every ```sh block of each
# page, in order, in one scratch folder holding copies of detectors/, spaces/ and priors/, with
# `hpge-cv` on the PATH. CI runs `bash docs/run-blocks.sh README.md docs/own-detector.md
# docs/python.md`; anyone can run it by hand.
#
#   bash docs/run-blocks.sh [--full] [--by-hand] PAGE.md...
#
# A block may carry a marker, an HTML comment on the line before its fence (the page says the
# same in words):
#   <!-- ci: test size: s|OLD|NEW|; s|OLD2|NEW2| -->  without --full the block runs with these
#       sed replacements (fewer rows, pulses, draws); --full runs it as printed.
#   <!-- ci: by hand ... -->  too long for CI, or CI runs it as its own step: skipped unless
#       --by-hand, which runs it in the repository root.
# hpge-cv is $HPGE_CV_BIN, else target/release/hpge-cv, else target/debug/hpge-cv (build one
# first: cargo build --release). The scratch folder is kept when a block fails, and named.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"

FULL=0
BY_HAND=0
PAGES=()
for a in "$@"; do
  case "$a" in
    --full) FULL=1 ;;
    --by-hand) BY_HAND=1 ;;
    -h | --help)
      sed -n '2,18p' "$0"
      exit 0
      ;;
    -*)
      echo "run-blocks: unknown option $a" >&2
      exit 2
      ;;
    *) PAGES+=("$a") ;;
  esac
done
if [ ${#PAGES[@]} -eq 0 ]; then
  echo "run-blocks: name at least one page (e.g. docs/own-detector.md)" >&2
  exit 2
fi

BIN="${HPGE_CV_BIN:-}"
if [ -z "$BIN" ]; then
  for b in "$ROOT/target/release/hpge-cv" "$ROOT/target/debug/hpge-cv"; do
    if [ -x "$b" ]; then
      BIN="$b"
      break
    fi
  done
fi
if [ -z "$BIN" ] || [ ! -x "$BIN" ]; then
  echo "run-blocks: no hpge-cv binary (set HPGE_CV_BIN or run cargo build --release)" >&2
  exit 2
fi

WORK="$(mktemp -d "${TMPDIR:-/tmp}/hpge-cv-docs.XXXXXX")"
mkdir -p "$WORK/bin" "$WORK/run"
ln -s "$BIN" "$WORK/bin/hpge-cv"
cp -r "$ROOT/detectors" "$ROOT/spaces" "$ROOT/priors" "$WORK/run/"
export PATH="$WORK/bin:$PATH"
echo "run-blocks: hpge-cv is $BIN; the blocks run in $WORK/run"

passed=0
failed=0
skipped=0

# run_block PAGE LINE MARKER TEXT
run_block() {
  local page="$1" line="$2" marker="$3" text="$4" dir="$WORK/run"
  local where="$page:$line"
  if [[ "$marker" == "by hand"* ]]; then
    if [ "$BY_HAND" = 0 ]; then
      echo "== $where: skipped (${marker}; --by-hand runs it)"
      skipped=$((skipped + 1))
      return 0
    fi
    dir="$ROOT"
  elif [[ "$marker" == "test size:"* ]] && [ "$FULL" = 0 ]; then
    local exprs=() e
    IFS=';' read -ra parts <<< "${marker#test size:}"
    for e in "${parts[@]}"; do
      e="$(echo "$e" | sed 's/^ *//; s/ *$//')"
      [ -n "$e" ] && exprs+=(-e "$e")
    done
    echo "== $where: at test size (${marker#test size: })"
    text="$(printf '%s\n' "$text" | sed "${exprs[@]}")"
  else
    echo "== $where"
  fi
  printf '%s\n' "$text" | sed 's/^/   /'
  local start=$SECONDS
  if (cd "$dir" && bash -euo pipefail -c "$text"); then
    echo "== $where: ok ($((SECONDS - start)) s)"
    passed=$((passed + 1))
  else
    echo "== $where: FAILED (exit $?; the scratch folder $WORK is kept)"
    failed=$((failed + 1))
  fi
}

for page in "${PAGES[@]}"; do
  if [ ! -f "$page" ] && [ -f "$ROOT/$page" ]; then page="$ROOT/$page"; fi
  if [ ! -f "$page" ]; then
    echo "run-blocks: no page $page" >&2
    exit 2
  fi
  name="${page#"$ROOT"/}"
  in_block=0
  marker=""
  prev=""
  text=""
  start=0
  n=0
  while IFS= read -r l || [ -n "$l" ]; do
    n=$((n + 1))
    if [ "$in_block" = 0 ]; then
      if [ "$l" = '```sh' ]; then
        in_block=1
        text=""
        start=$n
        marker=""
        if [[ "$prev" =~ ^\<!--\ ci:\ (.*)\ --\>$ ]]; then marker="${BASH_REMATCH[1]}"; fi
      fi
      prev="$l"
    elif [ "$l" = '```' ]; then
      in_block=0
      run_block "$name" "$start" "$marker" "$text"
      prev="$l"
    else
      text+="$l"$'\n'
    fi
  done < "$page"
done

echo "run-blocks: $passed blocks ran, $failed failed, $skipped skipped"
echo "blocks: $passed passed, $failed failed, $skipped skipped"
if [ "$failed" -gt 0 ]; then exit 1; fi
rm -rf "$WORK"
