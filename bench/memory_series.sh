#!/usr/bin/env bash
# Purpose: peak memory (max RSS, /usr/bin/time -v) of a 2000-run quickstart without and with the per-step series and the report.
# Usage: bench/memory_series.sh [TRACKFLOW] [BASELINE_TRACKFLOW] [RUNS]
#   TRACKFLOW           this tree's CLI (default build/bin/trackflow)
#   BASELINE_TRACKFLOW  optional: a CLI built from the commit before the series existed, for "without"
# Needs GNU time (Debian package `time`). Prints one line per configuration, in kB.
set -eu
cd "$(dirname "$0")/.."
TF=${1:-build/bin/trackflow}
BASE=${2:-}
RUNS=${3:-2000}
P=pipelines/quickstart.yaml
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

peak() {  # peak LABEL COMMAND...: the command's max RSS in kB
  local label=$1
  shift
  /usr/bin/time -v "$@" > "$OUT/stdout" 2> "$OUT/time" || { cat "$OUT/time" >&2; exit 1; }
  printf '%-58s %8s kB\n' "$label" "$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$OUT/time")"
}

echo "quickstart, $RUNS runs, --threads 2, $(nproc) CPUs"
if [ -n "$BASE" ]; then
  peak "baseline build (no series): run" "$BASE" run "$P" --runs "$RUNS" --threads 2 --no-progress --out "$OUT/b"
fi
peak "run (series accumulated, not written)" "$TF" run "$P" --runs "$RUNS" --threads 2 --no-progress --out "$OUT/r"
peak "run --series (series written as CSV)" "$TF" run "$P" --runs "$RUNS" --threads 2 --no-progress --series --out "$OUT/s"
peak "report (series, track of run 0, HTML)" "$TF" report "$P" --runs "$RUNS" --threads 2 --no-progress --out "$OUT/h"
