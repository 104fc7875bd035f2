#!/usr/bin/env bash
# Purpose: wall time and peak memory of paper 003's 2500-run study (pipelines/monopulse_glint_ekf_vs_aekf.yaml) with --threads 2, and its peak memory against the number of runs.
# Usage: bench/paper003_study.sh [TRACKFLOW] [REPEATS]
#   TRACKFLOW  the CLI (default build/bin/trackflow); REPEATS timed repetitions of the full study (default 3)
# Needs GNU time (Debian package `time`). Prints the machine, the load average around each run, the wall
# time and CPU seconds of each repetition (the aim: <= 20 s wall), and max RSS for 250, 1000 and 2500 runs
# (the aim: flat).
set -eu
cd "$(dirname "$0")/.."
TF=${1:-build/bin/trackflow}
REPEATS=${2:-3}
P=pipelines/monopulse_glint_ekf_vs_aekf.yaml
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

echo "machine: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(awk '/MemTotal/ { printf "%.1f GiB", $2 / 1048576 }' /proc/meminfo)"
echo "command: $TF run $P --threads 2 --no-progress"

# run LABEL ARGS...: one timed run; prints wall seconds, max RSS and the load average before it.
run() {
  local label=$1
  shift
  local load
  load=$(cut -d' ' -f1-3 /proc/loadavg)
  /usr/bin/time -v "$TF" run "$P" --threads 2 --no-progress "$@" > "$OUT/stdout" 2> "$OUT/time" || {
    cat "$OUT/time" >&2
    exit 1
  }
  local wall rss cpu
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ { print $2 }' "$OUT/time")
  rss=$(awk -F': ' '/Maximum resident set size/ { print $2 }' "$OUT/time")
  # CPU seconds (user + system): on a shared box the wall time depends on the other jobs; CPU / 2 is
  # what the run takes when it has both cores.
  cpu=$(awk -F': ' '/User time/ { u = $2 } /System time/ { s = $2 } END { printf "%.1f", u + s }' "$OUT/time")
  printf '%-16s wall %8s   CPU %6s s   max RSS %7s kB   load before %s\n' "$label" "$wall" "$cpu" "$rss" "$load"
}

for i in $(seq "$REPEATS"); do run "2500 runs (#$i)"; done
for n in 250 1000 2500; do run "$n runs" --runs "$n"; done
