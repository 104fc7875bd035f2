#!/usr/bin/env bash
# Purpose: peak memory (max RSS, /usr/bin/time -v) of a 2000-run quickstart without and with the per-step series and the report.
# Usage: bench/memory_series.sh [TRACKFLOW] [BASELINE_TRACKFLOW] [RUNS] [REPEATS]
#   TRACKFLOW           this tree's CLI (default build/bin/trackflow)
#   BASELINE_TRACKFLOW  optional: a CLI built from the commit before the series existed, for "without"
# Needs GNU time (Debian package `time`). Prints one line per configuration, in kB.
set -eu
cd "$(dirname "$0")/.."
TF=${1:-build/bin/trackflow}
BASE=${2:-}
RUNS=${3:-2000}
REPEATS=${4:-5}
P=pipelines/quickstart.yaml
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

# peak LABEL COMMAND...: the command's max RSS in kB, REPEATS times: the median, then all values
# (with 2 threads the peak depends on how many finished runs wait for their turn to merge).
peak() {
  local label=$1 values=()
  shift
  for _ in $(seq "$REPEATS"); do
    /usr/bin/time -v "$@" > "$OUT/stdout" 2> "$OUT/time" || { cat "$OUT/time" >&2; exit 1; }
    values+=("$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$OUT/time")")
  done
  local sorted
  sorted=$(printf '%s\n' "${values[@]}" | sort -n | tr '\n' ' ')
  printf '%-52s median %6s kB   (%s)\n' "$label" "$(printf '%s\n' "${values[@]}" | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')" "$sorted"
}

# Each binary loads only the quickstart's plugins (and sink.track for the report) from its own
# build, so that the figures compare the same set of loaded libraries.
plugins_of() {  # plugins_of BINARY DIR
  mkdir -p "$2"
  for p in sim_trajectory sim_radar convert_classical filter_kalman sink_metrics sink_track; do
    f="$(dirname "$1")/../lib/trackflow/plugins/tfplugin_$p.so"
    if [ -f "$f" ]; then cp "$f" "$2/"; fi
  done
}
plugins_of "$TF" "$OUT/plugins"
[ -z "$BASE" ] || plugins_of "$BASE" "$OUT/base-plugins"

for threads in 1 2; do
  echo "quickstart, $RUNS runs, --threads $threads, $(nproc) CPUs, $REPEATS repeats"
  common=(--runs "$RUNS" --threads "$threads" --no-progress --no-default-plugins --plugin-path "$OUT/plugins")
  if [ -n "$BASE" ]; then
    peak "baseline build (before the series existed): run" "$BASE" run "$P" --runs "$RUNS" --threads "$threads" \
      --no-progress --no-default-plugins --plugin-path "$OUT/base-plugins" --out "$OUT/b"
  fi
  peak "run --set score.series=false (series off)" "$TF" run "$P" "${common[@]}" --set score.series=false --out "$OUT/o"
  peak "run (series on: accumulated, not written)" "$TF" run "$P" "${common[@]}" --out "$OUT/r"
  peak "run --series (series on, written as CSV)" "$TF" run "$P" "${common[@]}" --series --out "$OUT/s"
  peak "report (series, track of run 0, HTML)" "$TF" report "$P" "${common[@]}" --out "$OUT/h"
done
