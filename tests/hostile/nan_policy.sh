#!/usr/bin/env bash
# Purpose: no NaN or infinity enters or leaves silently: units finite after the unit, logs' overflowing values are bad rows, filters refuse a non-finite state (counted, node and time), sink.csv writes nan and fails the run.
set -u
source "$(dirname "$0")/lib.sh"

base > "$TMP/p.yaml"
expect_run "1e308 km is infinite in SI: refused" 2 "node 'radar': parameter 'sigma_range': '1e308 km' is not a finite number in SI" \
  -- "$TF" validate "$TMP/p.yaml" --set "radar.sigma_range=1e308 km"
expect_run "km400/km399 (inf/inf) is refused" 2 "power of 'km400' is too large" -- "$TF" validate "$TMP/p.yaml" --set "radar.sigma_range=1 km400/km399"
expect_run "an exponent that would overflow is refused" 2 "power of 'm2147483647' is too large" \
  -- "$TF" validate "$TMP/p.yaml" --set "radar.sigma_range=1 m2147483647*m2147483647"

# Logs: six filters on one log, every estimate into one sink.csv.
six() {
  cat <<YAML
pipeline: { name: nan, seed: 1, runs: 1 }
nodes:
  - { id: radar, type: source.csv, params: { path: $1, range_unit: km, angle_unit: rad $2 } }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm }
  - { id: dc, type: filter.decoupled, input: cm }
  - { id: ekf, type: filter.ekf, input: radar }
  - { id: ekfs, type: filter.ekf_spherical, input: radar }
  - { id: gt, type: filter.gain_transform, input: radar, params: { singer_sigma: 10 m/s2 } }
  - { id: ukf, type: filter.ukf, input: radar }
  - { id: log, type: sink.csv, inputs: [kf, dc, ekf, ekfs, gt, ukf] }
YAML
}
six "$INPUTS/overflow_km.csv" "" > "$TMP/overflow.yaml"
expect_run "a log value finite in km but not in m is a bad row" 2 \
  "overflow_km.csv:5: value overflows when converted to SI \(column range, value '1e306'\)" -- "$TF" run "$TMP/overflow.yaml" --out "$TMP/o"
six "$INPUTS/overflow_km.csv" ", on_bad_row: skip" > "$TMP/overflow_skip.yaml"
expect_run "... skipped and counted with on_bad_row: skip" 0 "skipped_rows +1" -- "$TF" run "$TMP/overflow_skip.yaml" --out "$TMP/o"

six "$INPUTS/tiny_interval.csv" "" > "$TMP/tiny.yaml"
expect_run "two rows 1e-170 s apart: all six filters run" 0 "wrote $TMP/tiny/log.csv" -- "$TF" run "$TMP/tiny.yaml" --out "$TMP/tiny"
expect_no "... and write no NaN or infinity" "nan|inf" "$TMP/tiny/log.csv"
expect_no "... and no estimate without a position" "^0,[^,]*,[^,]*,estimate,[01],," "$TMP/tiny/log.csv"
"$TF" run "$TMP/tiny.yaml" --out "$TMP/tiny" > "$TMP/tiny.txt" 2>&1
expect_no "... because the second row restarts the start (no state to refuse)" "non-finite" "$TMP/tiny.txt"

six "$INPUTS/huge_range.csv" "" > "$TMP/huge.yaml"
expect_run "a range of 1e300 km: the filters refuse the non-finite state, naming node and time" 0 \
  "warning: (ekf|ekfs|gt|ukf): the state at t=0\.[0-9]+ s came out non-finite \(NaN or infinity\); the step is refused" \
  -- "$TF" run "$TMP/huge.yaml" --out "$TMP/huge"
expect_run "... and count it" 0 "non_finite_state_refused +[1-9]" -- "$TF" run "$TMP/huge.yaml" --out "$TMP/huge"
expect_no "... and write no NaN or infinity" "nan|inf" "$TMP/huge/log.csv"

six "$INPUTS/range_zero.csv" "" | sed 's/range_unit: km/range_unit: m/' > "$TMP/zero.yaml"
expect_run "a target at range 0 (filter.gain_transform's singular point) runs" 0 "wrote $TMP/zero/log.csv" \
  -- "$TF" run "$TMP/zero.yaml" --out "$TMP/zero"
expect_no "... and writes no NaN or infinity" "nan|inf" "$TMP/zero/log.csv"

# A filter on the SDK front end whose state turns NaN, and a node outside it that lets NaN through.
MIS="$HOSTILE/misbehave"
{ base; printf '  - { id: nf, type: test.nan_filter, input: cm, params: { at: 0.5 s } }\n  - { id: log, type: sink.csv, inputs: [nf, truth] }\n'; } > "$TMP/nf.yaml"
expect_run "the front end refuses the NaN state of any filter" 0 \
  "warning: nf: the state at t=0\.500000 s came out non-finite" -- "$TF" run "$TMP/nf.yaml" --plugin-path "$MIS" --out "$TMP/nf"
expect_run "... counted once per run" 0 "non_finite_state_refused +2" -- "$TF" run "$TMP/nf.yaml" --plugin-path "$MIS" --out "$TMP/nf"
expect_no "... and nothing non-finite reaches the sink" "nan|inf" "$TMP/nf/log.csv"
{ base; printf '  - { id: leak, type: test.nan_estimates, input: cm }\n  - { id: log, type: sink.csv, inputs: [leak, truth] }\n'; } > "$TMP/leak.yaml"
expect_run "a NaN that reaches sink.csv fails the run, saying where" 2 \
  "node 'log' \(sink.csv from [^)]*\): wrote [0-9]+ non-finite value\(s\) \(nan/inf\) into $TMP/leak/log.csv, the first in run 0, t=0.2 s, column x" \
  -- "$TF" run "$TMP/leak.yaml" --plugin-path "$MIS" --out "$TMP/leak"
grep -q '^0,0.2,leak,estimate,0,nan,' "$TMP/leak/log.csv" || fail "the NaN is not written as nan"
echo "ok: and it is written as nan, not as an empty (missing) cell"
finish
