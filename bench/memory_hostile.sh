#!/usr/bin/env bash
# Purpose: the memory acceptance of issue 13, measured (not a timed test): peak RSS of a 2e6-row recorded log at --threads 2, and of a 1e6-step run through sink.csv.
# Usage: bench/memory_hostile.sh [TRACKFLOW] [REPEATS]
#   TRACKFLOW  the CLI to measure (default build/bin/trackflow); give an older build's to compare
# Needs GNU time (Debian package `time`) and python3 (to write the log). Prints kB; the limits
# are 300 MB and 200 MB (docs/performance.md, "Memory under hostile sizes").
set -eu
cd "$(dirname "$0")/.."
TF=${1:-build/bin/trackflow}
REPEATS=${2:-3}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

peak() {  # peak LABEL COMMAND...: the median max RSS of REPEATS runs, then all values
  local label=$1 values=()
  shift
  for _ in $(seq "$REPEATS"); do
    /usr/bin/time -v "$@" > "$OUT/stdout" 2> "$OUT/time" || { cat "$OUT/time" >&2; exit 1; }
    values+=("$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$OUT/time")")
  done
  printf '%-58s median %7s kB   (%s)\n' "$label" \
    "$(printf '%s\n' "${values[@]}" | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')" \
    "$(printf '%s\n' "${values[@]}" | sort -n | tr '\n' ' ')"
}

# A 2e6-row spherical log (about 73 MB): a target receding slowly at 10 Hz, with noise.
python3 - "$OUT/log.csv" <<'PY'
import random, sys
random.seed(1)
with open(sys.argv[1], "w") as f:
    f.write("time,range,azimuth,elevation\n")
    for k in range(2_000_000):
        f.write(f"{k * 0.1:.1f},{10000 + 0.01 * k + random.gauss(0, 10):.3f},"
                f"{0.5 + random.gauss(0, 0.001):.6f},{0.1 + random.gauss(0, 0.001):.6f}\n")
PY
cat > "$OUT/log.yaml" <<YAML
pipeline: { name: big_log, seed: 1, runs: 2 }
nodes:
  - { id: radar, type: source.csv, params: { path: $OUT/log.csv, angle_unit: rad } }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm, params: { q: 0.01 m2/s3 } }
YAML
cat > "$OUT/steps.yaml" <<'YAML'
pipeline: { name: million_steps, seed: 1, runs: 1 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [6 km, 8 km, 1 km]
      initial_velocity: [-1 m/s, 0.5 m/s, 0 m/s]
      segments: [ { type: constant_velocity, duration: 99999.9 s } ]
  - { id: radar, type: sim.radar, input: truth, params: { sigma_range: 10 m, sigma_azimuth: 1 mrad, sigma_elevation: 1 mrad } }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm, params: { q: 0.01 m2/s3 } }
  - { id: log, type: sink.csv, inputs: [kf, truth] }
YAML
echo "$(du -h "$OUT/log.csv" | cut -f1) log, $(nproc) cores, $("$TF" --version)"
peak "2e6-row log, source.csv, 2 runs, --threads 2 (limit 300 MB)" "$TF" run "$OUT/log.yaml" --threads 2 --no-progress --out "$OUT/o1"
peak "1e6 steps through sink.csv, 1 run (limit 200 MB)" "$TF" run "$OUT/steps.yaml" --no-progress --out "$OUT/o2"
echo "sink.csv wrote $(wc -l < "$OUT/o2/log.csv") lines ($(du -h "$OUT/o2/log.csv" | cut -f1))"
