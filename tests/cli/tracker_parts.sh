#!/usr/bin/env bash
# Purpose: a tracker part (assoc.*, init.*, delete.*) given as a node of the graph is refused at its type's line, saying where it belongs; `describe` shows tracker.multi's component parameters and the parts' kinds; per-track adapters (tracker.multi adapters:) the estimator cannot serve are refused at their entry's line, and the others' values reach sink.csv's track rows under <tracker id>.<adapter type>.<name>.
set -u
TF=$1
source "$(dirname "$0")/lib.sh"

truth_radar parts 1 1 5 > "$TMP/part_node.yaml"
cat >> "$TMP/part_node.yaml" <<YAML
    params: {}
  - { id: gnn, type: assoc.gnn, input: radar }
YAML
line=$(grep -n "type: assoc.gnn" "$TMP/part_node.yaml" | cut -d: -f1)
expect_run "a tracker part as a node refused at its type" 2 \
  "part_node.yaml:$line:[0-9]+: node 'gnn': assoc.gnn is a tracker's associator, not a node: give it inside a tracker" \
  -- "$TF" validate "$TMP/part_node.yaml"

expect_run "describe tracker.multi lists its parts" 0 "associator .*component" -- "$TF" describe tracker.multi
expect_run "plugins lists the parts with their kinds" 0 "init.m_of_n +initiator" -- "$TF" plugins

# Per-track adapters on a tracker of sim.scenario's scans: adapt.range_r (a spherical R) on a
# filter.kalman estimator (a Cartesian R) refused at its entry's `type:` line, before anything runs.
tracker_with() {
  cat <<YAML
pipeline: { name: adapters, seed: 1, runs: 2 }
nodes:
  - id: scenario
    type: sim.scenario
    params:
      duration: 20 s
      planar: true
      region_lo: [-1 km, -1 km]
      region_hi: [1 km, 1 km]
      targets:
        - { initial_position: [-400 m, 0 m, 0 m], initial_velocity: [10 m/s, 0 m/s, 0 m/s] }
        - { initial_position: [400 m, 100 m, 0 m], initial_velocity: [-10 m/s, 0 m/s, 0 m/s] }
      measurement_sigma: 5 m
      clutter_rate: 1
  - id: mtt
    type: tracker.multi
    input: scenario
    params:
      estimator: { type: filter.kalman, q: 0.05 m2/s3 }
      adapters:
        - { type: adapt.innovation_r, window: 10, warmup: 3 }
$1
      associator: { type: assoc.gnn }
      initiator: { type: init.m_of_n, m: 2, n: 3, max_speed: 30 m/s }
      deleter: { type: delete.misses }
  - id: tracks
    type: sink.csv
    inputs: [mtt, scenario]
    params: { path: tracks.csv }
YAML
}
tracker_with "        - { type: adapt.range_r, alpha: 400 urad2, beta: 900 urad2, reference_range: 10 km }" \
  > "$TMP/bad_adapter.yaml"
line=$(grep -n "type: adapt.range_r" "$TMP/bad_adapter.yaml" | cut -d: -f1)
expect_run "a per-track adapter the estimator cannot serve refused at its entry" 2 \
  "bad_adapter.yaml:$line:[0-9]+: node 'mtt': cannot run adapter adapt.range_r on the tracks of tracker.multi .*spherical" \
  -- "$TF" validate "$TMP/bad_adapter.yaml"
tracker_with "" > "$TMP/adapters.yaml"
expect_run "per-track adapters run" 0 "" -- "$TF" run "$TMP/adapters.yaml" -o "$TMP/out"
head -1 "$TMP/out/tracks.csv" | grep -q "mtt.adapt.innovation_r.sigma_x,mtt.adapt.innovation_r.sigma_y,mtt.adapt.innovation_r.sigma_z" ||
  fail "sink.csv's header names no per-track adapter columns: $(head -1 "$TMP/out/tracks.csv")"
# Every track row carries its adapter's values (the last three columns; an empty cell would be no value).
awk -F, 'NR > 1 && $4 == "track" && $NF == "" { bad = 1 } END { exit bad }' "$TMP/out/tracks.csv" ||
  fail "a track row of tracks.csv has no adapter value"
echo "ok: per-track adapters refused at their entry, their values in sink.csv's track rows"
checks=$((checks + 1))

finish
