#!/usr/bin/env bash
# Purpose: the engine closes an instant once every source has emitted all of its time: two truth sources at 10 Hz and 4 Hz into one sim.scan_radar give one look per distinct time (121 in 10 s), each with every target of that time, for any --threads and in every run.
set -u
TF=$1
source "$(dirname "$0")/lib.sh"

cat > "$TMP/instants.yaml" <<'YAML'
pipeline: { name: instants, seed: 3, runs: 4 }
nodes:
  - id: fast
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [10 km, 20 km, 1 km]
      initial_velocity: [100, 0, 0]
      segments: [ { type: constant_velocity, duration: 10 s } ]
  - id: slow
    type: sim.trajectory
    params:
      rate: 4 Hz
      target: 1
      initial_position: [-10 km, 30 km, 2 km]
      initial_velocity: [0, 50, 0]
      segments: [ { type: constant_velocity, duration: 10 s } ]
  - id: radar
    type: sim.scan_radar
    inputs: [fast, slow]
    params: { range_max: 100 km }
YAML
# 101 samples at 10 Hz, 41 at 4 Hz, 21 times in common (every 0.5 s): 121 looks, 142 detections.
for threads in 1 2; do
  expect_run "one look per distinct time, --threads $threads" 0 "looks +121$" -- "$TF" run "$TMP/instants.yaml" --threads $threads
  expect_run "every target of an instant in its look, --threads $threads" 0 "target_detections +142$" -- \
    "$TF" run "$TMP/instants.yaml" --threads $threads
done
# A single source emitting its targets one item at a time (sim.trajectory) still closes each instant.
sed -i 's/inputs: \[fast, slow\]/inputs: [fast]/' "$TMP/instants.yaml"
expect_run "a single source: one look per sample" 0 "looks +101$" -- "$TF" run "$TMP/instants.yaml"
finish
