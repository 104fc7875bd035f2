#!/usr/bin/env bash
# Purpose: every kind of configuration error exits 2 with file:line:col and the node id.
set -u
TF=$1
source "$(dirname "$0")/lib.sh"

# A valid base pipeline; each case below breaks one thing.
base() { base_pipeline errors 1; }

base > "$TMP/ok.yaml"
expect_run "valid pipeline validates" 0 "ok" -- "$TF" validate "$TMP/ok.yaml"
# 5 s at 10 Hz, both ends included: 51 measurements, each gives the filter one estimate.
expect_run "the summary counts measurements processed and their rate" 0 "measurements processed: 51 by 1 filter \([0-9.e+]+ measurements/s\)" \
  -- "$TF" run "$TMP/ok.yaml" --out "$TMP/out"

base | sed 's/type: filter.kalman/type: filter.kalmn/' > "$TMP/unknown_type.yaml"
expect_run "unknown type" 2 "unknown_type.yaml:18:11: node 'kf': unknown type 'filter.kalmn' \(did you mean 'filter.kalman'\?\). Available: .*sink.metrics" \
  -- "$TF" validate "$TMP/unknown_type.yaml"
base | sed 's/type: filter.kalman/type: acme.alphabeta_tracker/' > "$TMP/third_party.yaml"
expect_run "an unknown third-party type suggests --plugin-path" 2 "unknown type 'acme.alphabeta_tracker'\. Available: .*A type from another plugin: give its folder with --plugin-path DIR" \
  -- "$TF" validate "$TMP/third_party.yaml"
mkdir -p "$TMP/misnamed"
cp "$(ls "$(dirname "$TF")"/../lib/trackflow/plugins/tfplugin_*.so | head -1)" "$TMP/misnamed/alphabeta.so"
expect_run "a misnamed plugin file in a plugin folder is named" 2 "not loaded: '$TMP/misnamed/alphabeta.so' \(plugin files are named tfplugin_<name>.so\)" \
  -- "$TF" validate "$TMP/third_party.yaml" --plugin-path "$TMP/misnamed"
base | sed 's/type: filter.kalman/type: filter.UKF/' > "$TMP/upper_type.yaml"
expect_run "a type in the wrong letter case is suggested in the right one" 2 "unknown type 'filter.UKF' \(did you mean 'filter.ukf'\?\)" \
  -- "$TF" validate "$TMP/upper_type.yaml"

base | sed 's/sigma_range: 10 m/sigma_rnge: 10 m/' > "$TMP/unknown_param.yaml"
expect_run "unknown parameter, with suggestion" 2 "unknown_param.yaml:13:15: node 'radar': unknown parameter 'sigma_rnge' \(did you mean 'sigma_range'\?\)" \
  -- "$TF" validate "$TMP/unknown_param.yaml"

base | sed '/initial_position/d' > "$TMP/missing.yaml"
expect_run "missing required parameter" 2 "missing.yaml:[0-9]+:[0-9]+: node 'truth': missing required parameter 'initial_position'" \
  -- "$TF" validate "$TMP/missing.yaml"

base | sed 's/rate: 10 Hz/rate: fast/' > "$TMP/wrong_type.yaml"
expect_run "wrong type" 2 "wrong_type.yaml:6:13: node 'truth': parameter 'rate': 'fast' is not a number" \
  -- "$TF" validate "$TMP/wrong_type.yaml"

base | sed 's/sigma_range: 10 m/sigma_range: 3 mrad/' > "$TMP/wrong_unit.yaml"
expect_run "wrong unit dimension" 2 "wrong_unit.yaml:13:28: node 'radar': parameter 'sigma_range' has unit dimension m, but '3 mrad' is rad" \
  -- "$TF" validate "$TMP/wrong_unit.yaml"

# Issue 26: a bare number for an angle or an angular rate is refused, with its SI reading; a length
# given bare stays what SI says, and zero needs no unit.
base | sed 's/sigma_range: 10 m/sigma_range: 10 m, sigma_azimuth: 2/' > "$TMP/bare_angle.yaml"
expect_run "a bare angle is refused with its SI reading" 2 "bare_angle.yaml:13:49: node 'radar': parameter 'sigma_azimuth' is an angle: write its unit \('2 deg', '2 mrad' or '2 rad'\); a bare 2 would be read as 2 rad = 114.592 deg" \
  -- "$TF" validate "$TMP/bare_angle.yaml"
base | sed 's/segments: .*/segments: [ { type: turn, turn_rate: 3, duration: 5 s } ]/' > "$TMP/bare_turn.yaml"
expect_run "a bare turn rate is refused with its SI reading" 2 "bare_turn.yaml:9:44: node 'truth': parameter 'turn_rate' is a quantity in rad/s: write its unit \('3 deg/s' or '3 rad/s'\); a bare 3 would be read as 3 rad/s = 171.887 deg/s" \
  -- "$TF" validate "$TMP/bare_turn.yaml"
expect_run "--set of a bare angle is refused too" 2 "node 'radar': parameter 'sigma_azimuth' is an angle: write its unit" \
  -- "$TF" validate "$TMP/ok.yaml" --set radar.sigma_azimuth=0.002
base | sed 's/segments: .*/segments: [ { type: turn, turn_rate: 0, duration: 5 s } ]/' | sed 's/sigma_range: 10 m/sigma_range: 10/' > "$TMP/bare_zero.yaml"
expect_run "a bare zero angle and a bare length are accepted" 0 "ok" -- "$TF" validate "$TMP/bare_zero.yaml"
# ... and a valid value that is seldom meant is a warning at validate (and once at run), not an error.
base | sed 's/sigma_range: 10 m/sigma_range: 10 m, sigma_azimuth: 0.5 rad/' > "$TMP/wide_angle.yaml"
expect_run "an angle sigma above 0.3 rad is warned about" 0 "warning: .*wide_angle.yaml:13:49: node 'radar': parameter 'sigma_azimuth' = '0.5 rad' is valid but implausible: an angle noise sigma above 0.3 rad \(17.2 deg\)" \
  -- "$TF" validate "$TMP/wide_angle.yaml"
base | sed 's/segments: .*/segments: [ { type: turn, turn_rate: 3 rad\/s, duration: 5 s } ]/' > "$TMP/hard_turn.yaml"
expect_run "a turn above 30 g is warned about" 0 "warning: .*hard_turn.yaml:9:44: node 'truth': parameter 'turn_rate': segment 1 \(turn\): 171.9 deg/s at 158.1 m/s horizontal speed is a 48.4 g turn, above the 30 g" \
  -- "$TF" validate "$TMP/hard_turn.yaml"
"$TF" run "$TMP/hard_turn.yaml" --runs 3 --out "$TMP/hard" --no-progress > "$TMP/hard.log" 2>&1 || fail "a run with a warning failed: $(cat "$TMP/hard.log")"
[ "$(grep -c 'g turn, above the 30 g' "$TMP/hard.log")" -eq 1 ] || fail "run: the turn warning is not printed exactly once: $(cat "$TMP/hard.log")"
echo "ok: run prints the warning once, whatever the number of runs"
checks=$((checks + 1))
# A log in km read as metres: every range under 100 m.
printf 'time,range,azimuth,elevation\n0,10,30,1\n1,10.1,30.2,1\n2,10.2,30.4,1\n' > "$TMP/km_log.csv"
cat > "$TMP/km_log.yaml" <<YAML
pipeline: {name: km_log, seed: 1, runs: 1}
nodes:
  - id: radar
    type: source.csv
    params: {path: km_log.csv, sigma_range: 20 m}
  - id: conv
    type: convert.classical
    input: radar
YAML
expect_run "a log whose every range is under 100 m is warned about" 0 "warning: .*km_log.yaml:5:20: node 'radar': parameter 'path': every range in '.*km_log.csv' is under 100 m \(the largest is 10.2 m, read with range_unit: m\): a log in km read as metres\? give range_unit: km" \
  -- "$TF" validate "$TMP/km_log.yaml"
out=$("$TF" validate "$TMP/km_log.yaml" --set radar.range_unit=km 2>&1) || fail "the km log does not validate with range_unit: km: $out"
printf '%s\n' "$out" | grep -q warning && fail "range_unit: km still warns: $out"
echo "ok: with range_unit: km the same log validates without a warning"
checks=$((checks + 1))

base | sed 's/- id: cm/- id: radar/' > "$TMP/duplicate.yaml"
expect_run "duplicate id" 2 "duplicate.yaml:14:5: node 'radar': duplicate node id 'radar' \(first defined at .*duplicate.yaml:10:5\)" \
  -- "$TF" validate "$TMP/duplicate.yaml"

base | sed 's/input: cm/input: cmm/' > "$TMP/dangling.yaml"
expect_run "dangling input" 2 "dangling.yaml:19:12: node 'kf': input 'cmm' is not a node \(did you mean 'cm'\?\)" \
  -- "$TF" validate "$TMP/dangling.yaml"

# cm takes cm2's output and cm2 takes cm's: kinds match, only the cycle is wrong.
{ base | sed 's/input: radar/input: cm2/'; printf '  - id: cm2\n    type: convert.classical\n    input: cm\n'; } > "$TMP/cycle.yaml"
expect_run "cycle" 2 "cycle.yaml:(14|25):5: node 'cm2?': the graph has a cycle: (cm -> cm2 -> cm|cm2 -> cm -> cm2) " \
  -- "$TF" validate "$TMP/cycle.yaml"

base | sed 's/input: radar/input: truth/' > "$TMP/wrong_kind.yaml"
expect_run "input of the wrong kind (truth into a converter)" 2 "wrong_kind.yaml:16:12: node 'cm': input 'truth' \(sim.trajectory\) produces truth, but convert.classical accepts measurement" \
  -- "$TF" validate "$TMP/wrong_kind.yaml"

{ base; printf '  - id: cm2\n    type: convert.classical\n    input: kf\n'; } > "$TMP/estimate_into_converter.yaml"
expect_run "an estimate into a converter" 2 "estimate_into_converter.yaml:25:12: node 'cm2': input 'kf' \(filter.kalman\) produces estimate, but convert.classical accepts measurement" \
  -- "$TF" validate "$TMP/estimate_into_converter.yaml"

printf 'pipeline: { name: x }\nnodes:\n  - id: a\n    type: [oops\n' > "$TMP/syntax.yaml"
expect_run "YAML syntax error" 2 "syntax.yaml:[0-9]+:[0-9]+: YAML syntax error" -- "$TF" validate "$TMP/syntax.yaml"

expect_run "--set of an unknown parameter" 2 "node 'kf': unknown parameter 'qq' \(did you mean 'q'\?\)" \
  -- "$TF" validate "$TMP/ok.yaml" --set kf.qq=3
expect_run "--set with a wrong unit" 2 "node 'radar': parameter 'sigma_range' has unit dimension m" \
  -- "$TF" validate "$TMP/ok.yaml" --set "radar.sigma_range=3 mrad"
expect_run "missing file" 2 "cannot open pipeline file" -- "$TF" validate "$TMP/nope.yaml"
expect_run "unknown command" 2 "unknown command 'rnu' \(did you mean 'run'\?\)" -- "$TF" rnu
expect_run "describe an unknown type" 2 "did you mean 'sim.radar'" -- "$TF" describe sim.rdar
# Issue 26: describe opens with the node as a pipeline writes it; with its placeholder replaced
# by a real input, that node validates.
"$TF" describe sim.radar > "$TMP/describe.txt" 2>&1 || fail "describe sim.radar failed"
sed -n 4,6p "$TMP/describe.txt" | tr '\n' '|' | grep -qx '  - id: radar|    type: sim.radar|    input: <a node producing truth>|' ||
  fail "describe sim.radar does not open with a YAML example: $(head -8 "$TMP/describe.txt")"
{ truth_radar describe_example 1 1 2 | sed '/^  - id: radar$/,$d'; sed -n '4,6p' "$TMP/describe.txt" | sed 's/<a node producing truth>/truth/'; } \
  > "$TMP/describe_example.yaml"
expect_run "describe's example, its input filled in, validates" 0 "ok" -- "$TF" validate "$TMP/describe_example.yaml"
expect_run "run --help documents exit codes and options" 0 "--threads" -- "$TF" run --help
expect_run "top-level help lists commands and exit codes" 0 "Exit codes: 0 ok, 1 an .expect. check failed, 2 bad" -- "$TF" --help

# Geodetic sites: written once at the top level, handed to the nodes that declare them; their
# field errors point at the sites: lines and name the node that read them.
geo() {
  printf 'pipeline: { name: geo, seed: 1, runs: 1, frame_origin: %s }\n' "$1"
  printf 'sites:\n  naro: { latitude: 34.43 deg, longitude: 127.53 deg }\n  jeju: { latitude: %s, longitude: 126.46 deg }\n' "$2"
  printf 'nodes:\n  - id: truth\n    type: sim.trajectory\n    params: { profile: kslv1, earth: wgs84, pad_site: naro, launch_azimuth: 170 deg, profile_duration: 2 s }\n'
  printf '  - id: radar\n    type: sim.radar\n    input: truth\n    params: { site: jeju }\n'
}
geo jeju "33.28 deg" > "$TMP/geo_ok.yaml"
expect_run "geodetic sites validate" 0 "ok" -- "$TF" validate "$TMP/geo_ok.yaml"
geo jej "33.28 deg" > "$TMP/geo_origin.yaml"
expect_run "frame_origin names no site" 2 "geo_origin.yaml:1:56: frame_origin 'jej' is not a site \(did you mean 'jeju'\?\); sites: naro, jeju" \
  -- "$TF" validate "$TMP/geo_origin.yaml"
geo jeju "33.28 m" > "$TMP/geo_unit.yaml"
expect_run "a site field with the wrong unit" 2 "geo_unit.yaml:4:21: node 'truth': parameter 'latitude' has unit dimension rad" \
  -- "$TF" validate "$TMP/geo_unit.yaml"
{ base | sed 's/^pipeline: .*$/pipeline: { name: errors, seed: 1, runs: 1 }\nsites: { naro: { latitude: 34.43 deg, longitude: 127.53 deg } }/'; } > "$TMP/geo_unused.yaml"
expect_run "sites without frame_origin" 2 "geo_unused.yaml:2:8: 'sites' needs 'frame_origin: <site>'" \
  -- "$TF" validate "$TMP/geo_unused.yaml"

printf 'expect:\n  score.position_rmse: { max: 0.001 }\n' > "$TMP/fail_tail.yaml"
{ base; cat "$TMP/fail_tail.yaml"; } > "$TMP/expect_fail.yaml"
expect_run "a failed expect exits 1" 1 "FAIL  score.position_rmse" -- "$TF" run "$TMP/expect_fail.yaml" --out "$TMP/out"
{ base; printf 'expect:\n  score.position_rmsee: { max: 1 }\n'; } > "$TMP/expect_typo.yaml"
expect_run "an expect naming a missing metric is a config error" 2 "has no metric 'position_rmsee' \(did you mean 'position_rmse'\?\)" \
  -- "$TF" run "$TMP/expect_typo.yaml" --out "$TMP/out"
{ base | sed 's/inputs: \[kf, truth\]/inputs: [kf]/'; printf 'expect:\n  score.position_rmse: { max: 1 }\n'; } > "$TMP/expect_no_truth.yaml"
expect_run "a metric missing for a reason says the reason" 2 "has no metric 'position_rmse'; it reports: .*; its notes say: no truth input" \
  -- "$TF" run "$TMP/expect_no_truth.yaml" --out "$TMP/out"
{ base; printf 'expect:\n  score.position_rmse: { less_than: score.velocity_rmsee }\n'; } > "$TMP/expect_ref.yaml"
expect_run "a less_than reference to a missing metric is a config error" 2 "has no metric 'velocity_rmsee' \(did you mean 'velocity_rmse'\?\)" \
  -- "$TF" run "$TMP/expect_ref.yaml" --out "$TMP/out"
{ base; printf 'expect:\n  score.position_rmse: { greater_than: score.velocity_rmse }\n  score.anees_steps_in_band: { outside_band: 0.95 }\n'; } > "$TMP/expect_cmp.yaml"
expect_run "greater_than and outside_band are evaluated" 1 "score.position_rmse = [0-9.]+ > score.velocity_rmse = [0-9.]+" \
  -- "$TF" run "$TMP/expect_cmp.yaml" --out "$TMP/out"
# A dotted --set reaches into a component-valued parameter (tracker.multi's estimator, associator, ...).
cat > "$TMP/tracker.yaml" <<'YAML'
pipeline: { name: tracker_set, seed: 1, runs: 1 }
nodes:
  - id: scenario
    type: sim.scenario
    params: { duration: 3 s, region_lo: [0, 0, 0], region_hi: [100 m, 100 m, 10 m] }
  - id: mtt
    type: tracker.multi
    input: scenario
    params:
      estimator: { type: filter.kalman, q: 1 m2/s3 }
      associator: { type: assoc.gnn }
      initiator: { type: init.m_of_n, max_speed: 20 m/s }
      deleter: { type: delete.misses }
YAML
expect_run "--set into a component" 0 "ok" -- "$TF" validate "$TMP/tracker.yaml" --set mtt.estimator.q=4
expect_run "--set into a component checks its unit" 2 "node 'mtt': parameter 'q' has unit dimension m2/s3, but '3 m' is m" \
  -- "$TF" validate "$TMP/tracker.yaml" --set "mtt.estimator.q=3 m"
expect_run "--set into a component: unknown parameter" 2 "node 'mtt': unknown parameter 'qq' \(did you mean 'q'\?\)" \
  -- "$TF" validate "$TMP/tracker.yaml" --set mtt.estimator.qq=4
expect_run "--set into a misspelt component" 2 "tracker.yaml:6:5: node 'mtt': --set mtt.estimatr.q: node 'mtt' sets no 'estimatr' to reach into \(did you mean 'estimator'\?\)" \
  -- "$TF" validate "$TMP/tracker.yaml" --set mtt.estimatr.q=4
expect_run "--set into a scalar" 2 "'max_speed' is not a map|'deleter' is|sets no 'max_tracks'" \
  -- "$TF" validate "$TMP/tracker.yaml" --set mtt.max_tracks.q=4

# Issue 26: an index reaches into a list of records or of reals; a wrong index names what is there.
base | sed 's/segments: .*/segments: [ { type: constant_velocity, duration: 2 s }, { type: turn, turn_rate: 1 deg\/s, duration: 3 s } ]/' \
  > "$TMP/two_segments.yaml"
expect_run "--set into a list of records" 0 "ok" -- "$TF" validate "$TMP/two_segments.yaml" --set "truth.segments[1].turn_rate=3 deg/s"
expect_run "--set into a list of records checks the field" 2 "node 'truth': parameter 'turn_rate' is a quantity in rad/s: write its unit" \
  -- "$TF" validate "$TMP/two_segments.yaml" --set "truth.segments[1].turn_rate=3"
expect_run "--set past the end of a list" 2 "node 'truth': --set truth.segments\[5\].turn_rate: 'segments' has 2 elements \(indices 0 to 1\), so no \[5\]" \
  -- "$TF" validate "$TMP/two_segments.yaml" --set "truth.segments[5].turn_rate=3 deg/s"
expect_run "--set with an index into a scalar" 2 "'rate' is '10 Hz', not a list to index" \
  -- "$TF" validate "$TMP/two_segments.yaml" --set "truth.rate[0]=5 Hz"
expect_run "--set with a bad index" 2 "'\[x\]' is not a list index" \
  -- "$TF" validate "$TMP/two_segments.yaml" --set "truth.segments[x].turn_rate=3 deg/s"
"$TF" run "$TMP/two_segments.yaml" --set "truth.initial_position[0]=20 km" --out "$TMP/elem" --metrics-json "$TMP/elem.json" \
  --no-progress > "$TMP/elem.log" 2>&1 || fail "--set of a list element: the run failed: $(cat "$TMP/elem.log")"
"$TF" run "$TMP/two_segments.yaml" --out "$TMP/plain" --metrics-json "$TMP/plain.json" --no-progress > "$TMP/plain.log" 2>&1 ||
  fail "the plain run failed: $(cat "$TMP/plain.log")"
cmp -s "$TMP/elem.json" "$TMP/plain.json" && fail "--set truth.initial_position[0] changed nothing"
echo "ok: --set truth.initial_position[0] sets one element of a list of reals"
checks=$((checks + 1))

# Issue 26: every pipeline in pipelines/ validates, and without a warning (the bare-angle refusal
# and the plausibility checks must not trip over the project's own experiments).
ROOT=${4:?cli_errors.sh needs the repo root as its 4th argument}
for p in "$ROOT"/pipelines/*.yaml; do
  out=$("$TF" validate "$p" 2>&1) || { printf '%s\n' "$out" >&2; fail "$(basename "$p") does not validate"; }
  if printf '%s\n' "$out" | grep -qi 'warning'; then
    printf '%s\n' "$out" >&2
    fail "$(basename "$p") validates with a warning"
  fi
  checks=$((checks + 1))
done
echo "ok: every pipeline in pipelines/ validates without a warning"

finish
