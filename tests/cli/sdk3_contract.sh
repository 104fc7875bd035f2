#!/usr/bin/env bash
# Purpose: the typed filter–adapter contract and frame-typed ports: wrong wires and wrong attachments refused at validate time with file:line:col; invalid log rows coast every convert.* -> filter combination; adapted noise restored by the engine at every run, and by tracker.multi at every track (per-track adapters).
set -u
TF=$1
PLUGINS=$2
TEST_PLUGINS="$PLUGINS/../test-plugins"
source "$(dirname "$0")/lib.sh"

radar_nodes() { truth_radar contract 4 3 20; }

# 1. A spherical radar wired straight into a Cartesian-only filter.
{ radar_nodes; cat <<'YAML'
  - id: kf
    type: filter.kalman
    input: radar
YAML
} > "$TMP/radar_kalman.yaml"
expect_run "sim.radar -> filter.kalman refused at the input line" 2 \
  "radar_kalman.yaml:15:12: node 'kf': input 'radar' \(sim.radar\) produces spherical measurements, but filter.kalman takes cartesian/planar \(x-y\) measurements; insert a converter between them \(convert.classical" \
  -- "$TF" validate "$TMP/radar_kalman.yaml"

# 2. Adapters whose noise the filter does not have.
{ radar_nodes; cat <<'YAML'
  - id: gt
    type: filter.gain_transform
    input: radar
    params: { singer_sigma: 10 m/s2 }
  - id: qs
    type: adapt.quality_switch
    attach_to: gt
YAML
} > "$TMP/qs_gt.yaml"
expect_run "adapt.quality_switch on filter.gain_transform refused at attach_to" 2 \
  "qs_gt.yaml:19:16: node 'qs': cannot attach adapter 'qs' \(adapt.quality_switch\) to filter 'gt' \(filter.gain_transform\): the adapter writes process noise as spectral densities in m2/s5.*but the filter's process noise is 3 standard deviations in m/s2, per ENU axis" \
  -- "$TF" validate "$TMP/qs_gt.yaml"

{ radar_nodes; cat <<'YAML'
  - id: ekf
    type: filter.ekf
    input: radar
  - id: air
    type: adapt.innovation_r
    attach_to: ekf
YAML
} > "$TMP/ir_ekf.yaml"
expect_run "adapt.innovation_r on a spherical-R filter refused at attach_to" 2 \
  "ir_ekf.yaml:18:16: node 'air': cannot attach adapter 'air' \(adapt.innovation_r\) to filter 'ekf' \(filter.ekf\): the adapter writes R of Cartesian positions.*but the filter's R is R of \[range m, azimuth rad, elevation rad" \
  -- "$TF" validate "$TMP/ir_ekf.yaml"

# filter.ekf with constant velocity has q in m2/s3: the quality switch (white jerk) is refused too.
{ radar_nodes; cat <<'YAML'
  - id: ekf
    type: filter.ekf
    input: radar
  - id: qs
    type: adapt.quality_switch
    attach_to: ekf
YAML
} > "$TMP/qs_cv.yaml"
expect_run "adapt.quality_switch on a CV filter.ekf refused (m2/s3 is not m2/s5)" 2 \
  "node 'qs': cannot attach .* 3 spectral densities in m2/s3, per ENU axis" -- "$TF" validate "$TMP/qs_cv.yaml"

# 3. A recorded log with invalid rows through every converter into every Cartesian filter, and
# straight into every spherical one: the invalid rows are coasted and counted, never an error.
awk 'BEGIN {
  print "time,range,azimuth,elevation,valid";
  pi = atan2(0, -1);
  for (i = 0; i < 60; i++) {
    t = i * 0.5; x = 6000 - 150 * t; y = 8000 + 50 * t; z = 1000;
    r = sqrt(x * x + y * y + z * z);
    az = atan2(x, y) * 180 / pi; el = atan2(z, sqrt(x * x + y * y)) * 180 / pi;
    valid = (i % 10 == 7) ? 0 : 1;
    printf "%.1f,%.3f,%.6f,%.6f,%d\n", t, r + ((i * 7) % 5 - 2), az + ((i * 3) % 5 - 2) * 1e-3, el, valid;
  }
}' > "$TMP/log.csv"
invalid=$(awk -F, 'NR > 1 && $5 == 0' "$TMP/log.csv" | wc -l)
# coast_case LABEL NODES...: the log, then the given node lines (the last one is the filter, `f`);
# every invalid row must be coasted.
coast_case() {
  local label=$1
  shift
  { cat <<'YAML'
pipeline: { name: coast, seed: 1, runs: 1 }
nodes:
  - id: log
    type: source.csv
    params: { path: log.csv, valid_column: valid, sigma_range: 3 m, sigma_azimuth: 1 mrad, sigma_elevation: 1 mrad }
YAML
    printf '%s\n' "$@"; } > "$TMP/coast.yaml"
  expect_run "$label coasts the $invalid invalid rows" 0 "^  coasted +$invalid$" -- "$TF" run "$TMP/coast.yaml" --no-progress
}
for conv in convert.classical convert.debiased convert.unbiased convert.unbiased_modified; do
  for filt in filter.kalman filter.decoupled; do
    coast_case "$conv -> $filt" "  - { id: cm, type: $conv, input: log }" "  - { id: f, type: $filt, input: cm }"
  done
done
for filt in filter.ekf filter.ukf filter.ekf_spherical; do
  coast_case "$filt" "  - { id: f, type: $filt, input: log }"
done
coast_case filter.gain_transform "  - { id: f, type: filter.gain_transform, input: log, params: { singer_sigma: 5 m/s2 } }"

# 4. The engine restores adapted process noise at every run: test.q_ramp doubles q at every step
# and publishes the q it found; filter.kalman does not restore q itself. Every run's first
# estimate must see the configured q (2), and the output must not depend on the thread count.
{ radar_nodes; classical_kalman; cat <<'YAML'
    params: { q: 2 m2/s3, init: explicit, initial_position: [6000, 8000, 1000], initial_sigma_position: 100 m,
              initial_sigma_velocity: 200 m/s }   # initialised from the first measurement on
  - id: ramp
    type: test.q_ramp
    attach_to: kf
  - id: rows
    type: sink.csv
    inputs: [kf]
    params: { precision: 17 }
YAML
} > "$TMP/ramp.yaml"
expect_run "q_ramp pipeline runs (1 thread)" 0 "rows" -- "$TF" run "$TMP/ramp.yaml" --plugin-path "$TEST_PLUGINS" --threads 1 --no-progress --out "$TMP/t1"
expect_run "q_ramp pipeline runs (2 threads)" 0 "rows" -- "$TF" run "$TMP/ramp.yaml" --plugin-path "$TEST_PLUGINS" --threads 2 --no-progress --out "$TMP/t2"
head -n 1 "$TMP/t1/rows.csv" | grep -q ',ramp.q_seen$' || fail "sink.csv has no ramp.q_seen column: $(head -n 1 "$TMP/t1/rows.csv")"
cmp -s "$TMP/t1/rows.csv" "$TMP/t2/rows.csv" || fail "q_ramp: output differs between --threads 1 and 2"
# The first row of each run: the q seen before the first adaptation of that run.
firsts=$(awk -F, 'NR > 1 && !seen[$1]++ { print $NF }' "$TMP/t1/rows.csv" | sort -u)
[ "$firsts" = "2" ] || fail "q seen at the start of the runs: '$firsts', expected only the configured 2"
runs=$(awk -F, 'NR > 1 { print $1 }' "$TMP/t1/rows.csv" | sort -u | wc -l)
[ "$runs" -eq 4 ] || fail "expected 4 runs in rows.csv, found $runs"
checks=$((checks + 1)); echo "ok: every run starts from the configured q, identical for 1 and 2 threads"

# 4b. Per track in tracker.multi (adapters:): every track, in a fresh slot or one a deleted track
# (clutter tracks fail M-of-N all the time) or an earlier run left, starts from the configured q.
# test.q_ramp runs before each of the track's two initiating detections, so its first published
# estimate carries the q seen at the second: 2 x the configured 2 = 4, for every track.
cat > "$TMP/ramp_tracks.yaml" <<'YAML'
pipeline: { name: ramp_tracks, seed: 2, runs: 3 }
nodes:
  - id: scenario
    type: sim.scenario
    params:
      duration: 15 s
      planar: true
      region_lo: [-1 km, -1 km]
      region_hi: [1 km, 1 km]
      targets:
        - { initial_position: [-400 m, 0 m, 0 m], initial_velocity: [10 m/s, 0 m/s, 0 m/s] }
        - { initial_position: [400 m, 100 m, 0 m], initial_velocity: [-10 m/s, 0 m/s, 0 m/s] }
      measurement_sigma: 5 m
      clutter_rate: 20
  - id: mtt
    type: tracker.multi
    input: scenario
    params:
      estimator: { type: filter.kalman, q: 2 m2/s3 }
      adapters: [ { type: test.q_ramp } ]
      associator: { type: assoc.gnn }
      initiator: { type: init.m_of_n, max_speed: 200 m/s }
      deleter: { type: delete.misses }
  - id: rows
    type: sink.csv
    inputs: [mtt]
    params: { precision: 17 }
YAML
expect_run "q_ramp per track runs (1 thread)" 0 "rows" -- "$TF" run "$TMP/ramp_tracks.yaml" --plugin-path "$TEST_PLUGINS" --threads 1 --no-progress --out "$TMP/rt1"
expect_run "q_ramp per track runs (2 threads)" 0 "rows" -- "$TF" run "$TMP/ramp_tracks.yaml" --plugin-path "$TEST_PLUGINS" --threads 2 --no-progress --out "$TMP/rt2"
head -n 1 "$TMP/rt1/rows.csv" | grep -q ',mtt.test.q_ramp.q_seen$' || fail "sink.csv has no mtt.test.q_ramp.q_seen column: $(head -n 1 "$TMP/rt1/rows.csv")"
cmp -s "$TMP/rt1/rows.csv" "$TMP/rt2/rows.csv" || fail "q_ramp per track: output differs between --threads 1 and 2"
# The first row of each (run, track id): the q its adapter saw at the track's second detection.
firsts=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "track_id") id = i } NR > 1 && !seen[$1 "/" $id]++ { print $NF }' "$TMP/rt1/rows.csv" | sort -u)
[ "$firsts" = "4" ] || fail "q seen at the first estimate of the tracks: '$firsts', expected only 4 (2 x the configured 2)"
tracks=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "track_id") id = i } NR > 1 { print $1 "/" $id }' "$TMP/rt1/rows.csv" | sort -u | wc -l)
[ "$tracks" -gt 20 ] || fail "expected clutter tracks to come and go (slots reused), found only $tracks tracks"
checks=$((checks + 1)); echo "ok: every track of tracker.multi starts from the configured q ($tracks tracks), identical for 1 and 2 threads"


# 5. What set_inputs learns (InputInfo, SDK 0.5): an upstream filter's state layout by name and
# unit, and whether the input is time-ordered (every source upstream declares it).
{ radar_nodes; classical_kalman; cat <<'YAML'
  - id: probe
    type: test.input_probe
    inputs: [kf, radar, truth]
YAML
} > "$TMP/probe.yaml"
expect_run "a filter input carries the filter's state layout and its time order" 0 \
  "input kf: time_ordered=yes, state=\\[x\\(m\\) vx\\(m/s\\) y\\(m\\) vy\\(m/s\\) z\\(m\\) vz\\(m/s\\)\\]" -- \
  "$TF" run "$TMP/probe.yaml" --plugin-path "$TEST_PLUGINS" --threads 1 --no-progress --out "$TMP/probe"
expect_run "a measurement input carries no state layout" 0 "input radar: time_ordered=yes, state=\\[\\]" -- \
  "$TF" run "$TMP/probe.yaml" --plugin-path "$TEST_PLUGINS" --threads 1 --no-progress --out "$TMP/probe"

finish
