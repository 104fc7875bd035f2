#!/usr/bin/env bash
# Purpose: every operator of an expect entry is checked, nothing in it is ignored, numbers are strict, and validate refuses what run would refuse after the runs.
set -u
source "$(dirname "$0")/lib.sh"

with() { { base; printf 'expect:\n  %s\n' "$1"; } > "$TMP/$2.yaml"; }
run() { "$TF" run "$TMP/$1.yaml" --out "$TMP/out" --no-progress; }

with "score.position_rmse: { min: 0, max: 1000, equals: 0.001 }" three
expect_run "min, max and equals in one entry: equals is checked too" 1 "FAIL  score.position_rmse = [0-9.]+ == 0.001" -- run three
expect_run "... and min and max as well" 1 "pass  score.position_rmse = [0-9.]+ <= 1000" -- run three
with "score.anees: { max: 0.0001, min: 0 }" two_ops
expect_run "two operators: both are checked (not only the last)" 1 "FAIL  score.anees = [0-9.]+ <= 0.0001" -- run two_ops
with "score.position_rmse: { min: 0, max: 1000, tolerence: 3 }" typo
expect_run "an unknown key beside min and max is refused" 2 "typo.yaml:24:45: unknown key 'tolerence' in expect 'score.position_rmse' \(did you mean 'tolerance'\?\)" \
  -- "$TF" validate "$TMP/typo.yaml"
with "score.position_rmse: { max: 25abc }" suffix
expect_run "25abc is not 25" 2 "suffix.yaml:24:31: expect 'score.position_rmse': 'max' needs a finite number, got '25abc'" -- run suffix
with "score.bias_x: { equals: 0, tolerance: abc }" tolerance
expect_run "a non-numeric tolerance is exit 2, not an internal error" 2 "'tolerance' needs a finite number, got 'abc'" -- run tolerance
with "score.anees_steps_in_band: { within_band: 95 }" percent
expect_run "a band confidence given in percent is refused" 2 "is a confidence between 0 and 1" -- "$TF" validate "$TMP/percent.yaml"
with "scroe.position_rmse: { max: 25 }" node
expect_run "validate refuses an expect naming a node that does not exist" 2 \
  "node.yaml:24:3: expect names node 'scroe', which does not exist \(did you mean 'score'\?\)" -- "$TF" validate "$TMP/node.yaml"
with "score.position_rmse: { less_than: kff.position_rmse }" ref
expect_run "... or a reference node that does not exist" 2 "expect names node 'kff'" -- "$TF" validate "$TMP/ref.yaml"
with "score.position_rmse: { max: 1000, min: 0 }" good
expect_run "a valid entry still passes" 0 "2 passed, 0 failed" -- run good
finish
