#!/usr/bin/env bash
# Purpose: the memory acceptance of issue 12 point 4, measured (not a timed test): peak RSS, wall and CPU time of a 1e7-row recorded log replayed by source.csv at --threads 2.
# Usage: bench/memory_long_log.sh [TRACKFLOW] [ROWS] [REPEATS]
#   TRACKFLOW  the CLI to measure (default build/bin/trackflow); give an older build's to compare
#   ROWS       data rows of the generated log (default 10000000, about 370 MB of CSV)
#   REPEATS    runs of each case; the median max RSS is printed with every value (default 1)
# Env: LONG_LOG_DIR=DIR keeps the generated log in DIR (reused when it has ROWS rows) instead of a
# temporary folder; METRICS_ROWS=N also scores an N-row log with sink.metrics, series: false,
# then with sink.metrics' defaults (series: true) (default ROWS, the same log; 0: skip). Needs GNU
# time (Debian package `time`) and python3. The limits are 150 MB without and 100 MB with
# sink.metrics (docs/performance.md, "Memory flat in the length of a recorded log", issue 20
# point 7, issue 27).
set -eu
cd "$(dirname "$0")/.."
TF=${1:-build/bin/trackflow}
ROWS=${2:-10000000}
REPEATS=${3:-1}
METRICS_ROWS=${METRICS_ROWS:-$ROWS}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
LOGS=${LONG_LOG_DIR:-$OUT}
mkdir -p "$LOGS"

# A spherical log: a target receding slowly at 10 Hz, with noise (as bench/memory_hostile.sh).
make_log() {  # make_log ROWS FILE
  [ -s "$2" ] && [ "$(head -c 64 "$2.rows" 2>/dev/null)" = "$1" ] && return
  python3 - "$1" "$2" <<'PY'
import random, sys
random.seed(1)
rows, path = int(sys.argv[1]), sys.argv[2]
with open(path, "w") as f:
    f.write("time,range,azimuth,elevation\n")
    for k0 in range(0, rows, 100000):
        f.write("".join(f"{k * 0.1:.1f},{10000 + 0.01 * k + random.gauss(0, 10):.3f},"
                        f"{0.5 + random.gauss(0, 0.001):.6f},{0.1 + random.gauss(0, 0.001):.6f}\n"
                        for k in range(k0, min(rows, k0 + 100000))))
PY
  echo "$1" > "$2.rows"
}

pipeline() {  # pipeline LOG [SINK-LINE]: 2 runs, source.csv -> convert.classical -> filter.kalman [-> sink]
  cat <<YAML
pipeline: { name: long_log, seed: 1, runs: 2 }
nodes:
  - { id: radar, type: source.csv, params: { path: $1, angle_unit: rad } }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm, params: { q: 0.01 m2/s3 } }
${2:-}
YAML
}

measure() {  # measure LABEL COMMAND...: median max RSS of REPEATS runs, all values, wall and CPU of each
  local label=$1 values=() times=()
  shift
  for _ in $(seq "$REPEATS"); do
    /usr/bin/time -v "$@" > "$OUT/stdout" 2> "$OUT/time" || { cat "$OUT/stdout" "$OUT/time" >&2; exit 1; }
    values+=("$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$OUT/time")")
    times+=("$(awk -F': ' '/Elapsed \(wall clock\)/ { w = $2 } /User time/ { u = $2 } /System time/ { s = $2 }
                           END { printf "wall %s, user %s s, sys %s s", w, u, s }' "$OUT/time")")
  done
  printf '%-62s median %8s kB   (%s)\n' "$label" \
    "$(printf '%s\n' "${values[@]}" | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')" \
    "$(printf '%s\n' "${values[@]}" | sort -n | tr '\n' ' ')"
  printf '    %s\n' "${times[@]}"
  grep -E "^ +(measurements processed:|rows|skipped_rows|updates|estimates|anis) " "$OUT/stdout" | sed 's/^ */    /' | paste -sd ';' || true
}

make_log "$ROWS" "$LOGS/long.csv"
pipeline "$LOGS/long.csv" > "$OUT/long.yaml"
echo "$(du -h "$LOGS/long.csv" | cut -f1) log of $ROWS rows, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $("$TF" --version)"
measure "$ROWS-row log, 2 runs, --threads 2 (limit 150 MB)" \
  "$TF" run "$OUT/long.yaml" --threads 2 --no-progress --out "$OUT/o1"
measure "$ROWS-row log, 2 runs, --threads 1" \
  "$TF" run "$OUT/long.yaml" --threads 1 --no-progress --out "$OUT/o2"

# sink.metrics on a time-ordered source without truth and series keeps sums per run only, so it
# is flat too (before issue 20 point 7 it kept every estimate and a table of every time step:
# ~1.7 GB for 10^6 rows). The same log is reused when METRICS_ROWS is ROWS.
if [ "$METRICS_ROWS" -gt 0 ]; then
  METRICS_LOG="$LOGS/long.csv"
  if [ "$METRICS_ROWS" != "$ROWS" ]; then
    METRICS_LOG="$LOGS/metrics.csv"
    make_log "$METRICS_ROWS" "$METRICS_LOG"
  fi
  pipeline "$METRICS_LOG" "  - { id: score, type: sink.metrics, inputs: [kf], params: { series: false } }" > "$OUT/metrics.yaml"
  measure "$METRICS_ROWS-row log + sink.metrics series: false, 2 runs, --threads 2 (limit 100 MB)" \
    "$TF" run "$OUT/metrics.yaml" --threads 2 --no-progress --out "$OUT/o3"
  # With its defaults (series: true, issue 27's case) the series is kept in at most 16 384 bins.
  pipeline "$METRICS_LOG" "  - { id: score, type: sink.metrics, inputs: [kf] }" > "$OUT/metrics_series.yaml"
  measure "$METRICS_ROWS-row log + sink.metrics (defaults), 2 runs, --threads 2 (limit 100 MB)" \
    "$TF" run "$OUT/metrics_series.yaml" --threads 2 --no-progress --out "$OUT/o4"
fi
