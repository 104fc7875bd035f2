#!/usr/bin/env bash
# Purpose: bounds with clear errors (sweep grid size) and bounded memory in sink.csv: a long run streams through a temporary file and gives the same file for any thread count.
set -u
source "$(dirname "$0")/lib.sh"

base > "$TMP/p.yaml"
expect_run "a sweep grid of 101 x 100 points is refused before anything is built" 2 "the sweep grid has more than 10000 points" \
  -- "$TF" sweep "$TMP/p.yaml" --param "kf.q=$(seq -s, 1 101)" --param "radar.sigma_range=$(seq -s, 1 100)"

# Three runs of 60 000 steps: 14 MB of rows per run, more than a run keeps in memory (4 MiB).
cat > "$TMP/long.yaml" <<'YAML'
pipeline: { name: long, seed: 3, runs: 3 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [6 km, 8 km, 1 km]
      initial_velocity: [-1 m/s, 0.5 m/s, 0 m/s]
      segments: [ { type: constant_velocity, duration: 6000 s } ]
  - { id: radar, type: sim.radar, input: truth }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm, params: { q: 0.01 m2/s3 } }
  - { id: log, type: sink.csv, inputs: [kf, truth] }
YAML
expect_run "long runs through sink.csv (1 thread)" 0 "rows +180000" -- "$TF" run "$TMP/long.yaml" --threads 1 --out "$TMP/t1"
expect_run "... (2 threads)" 0 "rows +180000" -- "$TF" run "$TMP/long.yaml" --threads 2 --out "$TMP/t2"
cmp "$TMP/t1/log.csv" "$TMP/t2/log.csv" || fail "the streamed file differs between 1 and 2 threads"
echo "ok: the streamed file is byte-identical for 1 and 2 threads"
[ "$(wc -l < "$TMP/t1/log.csv")" -eq 180001 ] || fail "the file does not have 180001 lines"
[ "$(cut -d, -f1 "$TMP/t1/log.csv" | uniq | tr '\n' ' ')" = "run 0 1 2 " ] || fail "the runs are not in order"
echo "ok: with every row, runs in order"
ls -A "$TMP/t1" | grep -qv '^log.csv$' && fail "temporary files were left: $(ls -A "$TMP/t1")"
echo "ok: and no temporary file is left"
checks=$((checks + 3))
finish
