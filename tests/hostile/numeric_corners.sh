#!/usr/bin/env bash
# Purpose: numeric corners that diverged with exit 0 (issue 27): filter.ukf on an exact zenith pass, filter.ekf and filter.ukf with q = 1e12 m2/s3, plausibility bounds (site height, beamwidth, state_scale, one input twice), a log's 1e300 azimuth and 1e-400 time, and range messages as an analyst reads them.
set -u
source "$(dirname "$0")/lib.sh"

# metric <json> <node.metric>: one value of --metrics-json.
metric() {
  python3 -c 'import json, sys
node, name = sys.argv[2].split(".", 1)
print(json.load(open(sys.argv[1]))[node][name]["value"])' "$1" "$2"
}
# expect_below <what> <json> <node.metric> <bound>: the value must be finite and below the bound.
expect_below() {
  local v
  v=$(metric "$2" "$3") || fail "$1: no $3 in $2"
  python3 -c 'import math, sys; v = float(sys.argv[1]); sys.exit(0 if math.isfinite(v) and v < float(sys.argv[2]) else 1)' \
    "$v" "$4" || fail "$1: $3 = $v, expected below $4"
  checks=$((checks + 1))
  echo "ok: $1 ($3 = $v < $4)"
}

# pass <filter> <y offset> <q>: a CV target 10 km up flying at 200 m/s along x through the point
# (0, y) above the radar at t = 30 s (y = 0: straight through the zenith), 20 runs of 60 s.
pass() {
  cat <<YAML
pipeline: { name: zenith, seed: 1, runs: 20 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [-6000 m, $2 m, 10 km]
      initial_velocity: [200 m/s, 0 m/s, 0 m/s]
      segments: [ { type: constant_velocity, duration: 60 s } ]
  - id: radar
    type: sim.radar
    input: truth
    params: { sigma_range: 10 m, sigma_azimuth: 1 mrad, sigma_elevation: 1 mrad }
  - { id: f, type: $1, input: radar, params: { q: $3 m2/s3 } }
  - { id: score, type: sink.metrics, inputs: [f, truth] }
YAML
}

# 1. An exact zenith pass with the matched model (q = 0 for this CV truth): the UKF drops the
# azimuth where filter.ekf does (before: RMSE 75 m, ANEES 3 047 against the EKF's 3.0 m and 1.0 on
# this pass). 100 m off the zenith both give 2.9 m.
for f in filter.ukf filter.ekf; do
  pass $f 0 0 > "$TMP/zenith_$f.yaml"
  expect_run "$f on an exact zenith pass runs" 0 "azimuth_dropped +[1-9]" \
    -- "$TF" run "$TMP/zenith_$f.yaml" --out "$TMP/o" --metrics-json "$TMP/zenith_$f.json"
  expect_below "... $f follows it" "$TMP/zenith_$f.json" score.position_rmse 5
  expect_below "... $f is consistent there" "$TMP/zenith_$f.json" score.anees 1.5
done
pass filter.ukf 0 0 > "$TMP/z.yaml"
expect_run "filter.ukf says once per run that it dropped the azimuth" 0 "warning: f: target near the zenith at t=[0-9.]+ s: azimuth not used" \
  -- "$TF" run "$TMP/z.yaml" --out "$TMP/o"
pass filter.ukf 100 0 > "$TMP/off.yaml"
expect_run "100 m off the zenith the UKF drops nothing" 0 "azimuth_dropped +0$" -- "$TF" run "$TMP/off.yaml" --out "$TMP/o" \
  --metrics-json "$TMP/off.json"
expect_below "... and follows the target" "$TMP/off.json" score.position_rmse 5

# 2. q = 1e12 m2/s3 (an 18 km sigma per 0.1 s step): the filters follow the measurements (filter.kalman
# on converted measurements: 18.3 m) instead of dropping the azimuth for the whole run (before: EKF
# 11 km, UKF 28 000 km), and say that they iterated the update.
for f in filter.ekf filter.ukf; do
  pass $f 8000 1e12 > "$TMP/q_$f.yaml"
  expect_run "$f with q = 1e12 m2/s3 says it iterated the update" 0 \
    "warning: f: predicted horizontal uncertainty more than 100 times the measurement's .* the update was iterated" \
    -- "$TF" run "$TMP/q_$f.yaml" --out "$TMP/o" --metrics-json "$TMP/q_$f.json"
  expect_below "... $f follows the measurements" "$TMP/q_$f.json" score.position_rmse 25
  expect_below "... $f is not overconfident" "$TMP/q_$f.json" score.anees 2
done

# 3. Plausibility bounds.
cat > "$TMP/site.yaml" <<'YAML'
pipeline: { name: site, seed: 1, runs: 1, frame_origin: radar_site }
sites:
  radar_site: { latitude: 34.4 deg, longitude: 127.5 deg, height: 1e8 m }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [6 km, 8 km, 1 km]
      initial_velocity: [-150 m/s, 50 m/s, 0 m/s]
      segments: [ { type: constant_velocity, duration: 5 s } ]
  - { id: radar, type: sim.radar, input: truth, params: { site: radar_site } }
  - { id: f, type: filter.ekf, input: radar }
YAML
expect_run "a radar site 1e8 m up is refused, with the bound in metres" 2 "parameter 'height' must be >= -11000 m and <= 100000 m, got '1e8 m'" \
  -- "$TF" validate "$TMP/site.yaml"
sed 's/height: 1e8 m/height: 100 km/' "$TMP/site.yaml" > "$TMP/site_ok.yaml"
expect_run "... 100 km is accepted" 0 "" -- "$TF" validate "$TMP/site_ok.yaml"

{
  truth_radar mono 1 1 5 | sed 's/type: sim.radar/type: sim.monopulse_radar/'
  echo "    params: { beamwidth: 1e6 deg }"
} > "$TMP/beam.yaml"
expect_run "a monopulse beamwidth of 1e6 deg is refused, with the bound in degrees" 2 \
  "parameter 'beamwidth' must be > 0 and <= 30 deg, got '1e6 deg'" -- "$TF" validate "$TMP/beam.yaml"

{
  truth_radar refr 1 1 5
  printf '  - { id: f, type: filter.refraction_ekf, input: radar, params: { state_scale: 1e-300 } }\n'
} > "$TMP/scale.yaml"
expect_run "filter.refraction_ekf's state_scale of 1e-300 is refused" 2 \
  "parameter 'state_scale' must be >= 1e-12 and <= 1000000, got '1e-300'" -- "$TF" validate "$TMP/scale.yaml"

{
  truth_radar fusion 1 1 5
  classical_kalman
  printf '  - { id: fused, type: filter.track_fusion, inputs: [kf, kf] }\n'
} > "$TMP/twice.yaml"
expect_run "filter.track_fusion refuses the same input twice" 2 "node 'fused'.*input 'kf' is listed twice" \
  -- "$TF" validate "$TMP/twice.yaml"

# 4. A log's implausible azimuth and a time below the smallest double.
log_pipeline() {
  printf 'pipeline: { name: log, seed: 1, runs: 1 }\nnodes:\n  - { id: radar, type: source.csv, params: { path: %s } }\n' "$1"
  printf '  - { id: f, type: filter.ekf, input: radar }\n'
}
printf 'time,range,azimuth,elevation\n0,10000,30,5\n0.1,10000,1e300,5\n0.2,10000,30,5\n' > "$TMP/spin.csv"
log_pipeline "$TMP/spin.csv" > "$TMP/spin.yaml"
expect_run "a 1e300 deg azimuth in a log is a bad row naming file:line" 2 "spin.csv:3: azimuth beyond \+-360 deg \(column azimuth, value '1e300'\)" \
  -- "$TF" validate "$TMP/spin.yaml"
sed "s|path: $TMP/spin.csv|path: $TMP/spin.csv, on_bad_row: skip|" "$TMP/spin.yaml" > "$TMP/spin_skip.yaml"
expect_run "... or, with on_bad_row: skip, left out and counted" 0 "skipped_rows +1" -- "$TF" run "$TMP/spin_skip.yaml" --out "$TMP/o"
printf 'time,range,azimuth,elevation\n1e-400,10000,30,5\n0.1,10000,30,5\n' > "$TMP/tiny.csv"
log_pipeline "$TMP/tiny.csv" > "$TMP/tiny.yaml"
expect_run "a time of 1e-400 is an underflow, not 'NaN or infinite'" 2 \
  "tiny.csv:2: number is too small for a double \(nonzero but below 4.9e-324 in magnitude: it underflows; write 0\) \(column time" \
  -- "$TF" validate "$TMP/tiny.yaml"
base > "$TMP/p.yaml"
expect_run "... as a parameter says the same" 2 "parameter 'q': '1e-400 m2/s3' is too small for a double" \
  -- "$TF" validate "$TMP/p.yaml" --set "kf.q=1e-400 m2/s3"

# 5. Range messages: no 4.94066e-324 and no unit "1" (issue 26).
{ base; } | sed 's/inputs: \[kf, truth\]/inputs: [kf, truth]\n    params: { confidence: 2 }/' > "$TMP/conf.yaml"
expect_run "a positive bounded number's range reads '> 0 and <= 1'" 2 "parameter 'confidence' must be > 0 and <= 1, got '2'" \
  -- "$TF" validate "$TMP/conf.yaml"
"$TF" validate "$TMP/conf.yaml" > "$TMP/conf.txt" 2>&1
expect_no "... without the smallest double" "4\.94066e-324|e-324" "$TMP/conf.txt"
finish
