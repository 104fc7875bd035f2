#!/usr/bin/env bash
# Purpose: the engine closes an instant once every source has emitted all of its time: two truth sources at 10 Hz and 4 Hz into one sim.scan_radar give one look per distinct time (121 in 10 s), each with every target of that time, for any --threads and in every run; a source.csv of detections is a scan source: a tracker takes it, a filter is refused at its input line; a truth log (content: truth) scores it; sink.csv writes the looks.
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
# The looks written by sink.csv: one detection row per target and look, origin = the target id.
cat >> "$TMP/instants.yaml" <<'YAML'
  - id: plots
    type: sink.csv
    inputs: [radar, fast, slow]
    params: { include_detections: true }
YAML
expect_run "sink.csv writes the scans" 0 "wrote .*plots.csv" -- "$TF" run "$TMP/instants.yaml" --out "$TMP/out"
rows=$(grep -c ',detection,' "$TMP/out/plots.csv")
[ "$rows" -eq $((4 * 142)) ] || fail "sink.csv wrote $rows detection rows, expected 4 runs x 142"
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "origin") o = i; next } $4 == "detection" && $o != 0 && $o != 1 { bad++ }
         END { exit bad > 0 || o == 0 }' "$TMP/out/plots.csv" || fail "sink.csv: a detection row without its target's origin"
checks=$((checks + 1))
echo "ok: every detection row has its origin"
sed -i '/id: plots/,$d' "$TMP/instants.yaml"
# A single source emitting its targets one item at a time (sim.trajectory) still closes each instant.
sed -i 's/inputs: \[fast, slow\]/inputs: [fast]/' "$TMP/instants.yaml"
expect_run "a single source: one look per sample" 0 "looks +101$" -- "$TF" run "$TMP/instants.yaml"

# A recorded detection log (content: detections) feeds a tracker; wired to a filter it is refused
# before anything runs, naming the filter's input line.
{
  echo "time,x,y,z"
  for k in 0 1 2 3 4 5 6 7 8 9; do echo "$k,$((10 * k)),5,0"; echo "$k,$((10 * k)),-300,0"; done
} > "$TMP/plots.csv"
cat > "$TMP/log.yaml" <<YAML
pipeline: { name: log, runs: 1 }
nodes:
  - id: log
    type: source.csv
    params: { path: plots.csv, content: detections, frame: cartesian, detection_probability: 0.9, clutter_density: 1e-9 }
  - id: mtt
    type: tracker.multi
    input: log
    params:
      estimator: { type: filter.kalman, q: 0.1 m2/s3 }
      associator: { type: assoc.gnn }
      initiator: { type: init.m_of_n, m: 2, n: 3, max_speed: 20 m/s }
      deleter: { type: delete.misses }
YAML
expect_run "a detection log through tracker.multi: two tracks" 0 "tracks_confirmed_per_run +2$" -- "$TF" run "$TMP/log.yaml"
expect_run "a detection log counts its scans" 0 "scans +10$" -- "$TF" run "$TMP/log.yaml"
# Recorded data scored: the same log against a truth log (content: truth) by sink.gospa.
{
  echo "time,target,x,y,z,vx,vy,vz"
  for k in 0 1 2 3 4 5 6 7 8 9; do echo "$k,0,$((10 * k)),5,0,10,0,0"; echo "$k,1,$((10 * k)),-300,0,10,0,0"; done
} > "$TMP/truth.csv"
# Sources tie at one time in declaration order, and a sink scores a track set against the truth
# already delivered for its time: the truth log is declared first. Declared after the detection log,
# every track set comes before its truth, which the sink counts and explains.
truth_node='  - id: truth
    type: source.csv
    params: { path: truth.csv, content: truth, frame: cartesian, vx_column: vx, vy_column: vy, vz_column: vz }'
gospa_node='  - id: gospa
    type: sink.gospa
    inputs: [mtt, truth]
    params: { cutoff: 20 m, skip_initial: 3 s }'
{ head -2 "$TMP/log.yaml"; echo "$truth_node"; tail -n +3 "$TMP/log.yaml"; echo "$gospa_node"; } > "$TMP/scored.yaml"
expect_run "a detection log scored against a truth log: both targets every step" 0 "truths +2$" -- "$TF" run "$TMP/scored.yaml"
expect_run "a detection log scored against a truth log: no step without its truth" 0 "steps_without_truth +0$" -- \
  "$TF" run "$TMP/scored.yaml"
expect_run "a detection log scored against a truth log: tracks on their targets" 0 "missed_targets +0$" -- \
  "$TF" run "$TMP/scored.yaml"
{ cat "$TMP/log.yaml"; echo "$truth_node"; echo "$gospa_node"; } > "$TMP/late_truth.yaml"
expect_run "truth declared after the scans: counted and explained" 0 \
  "steps_without_truth +7$" -- "$TF" run "$TMP/late_truth.yaml"
expect_run "truth declared after the scans: the note says what to do" 0 \
  "declare that source before the scan source" -- "$TF" run "$TMP/late_truth.yaml"
head -5 "$TMP/log.yaml" > "$TMP/filter.yaml"
printf '  - { id: mtt, type: filter.kalman,\n      input: log }\n' >> "$TMP/filter.yaml"
line=$(grep -n "input: log" "$TMP/filter.yaml" | cut -d: -f1)
expect_run "a detection log into a filter is refused at its input" 2 \
  "filter.yaml:$line:[0-9]+: node 'mtt': input 'log' \\(source.csv as configured\\) produces scan, but filter.kalman accepts measurement" \
  -- "$TF" validate "$TMP/filter.yaml"
finish
