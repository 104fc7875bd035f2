#!/usr/bin/env bash
# Purpose: filter.imm with modes given as components (issue 20): an EKF mode and a UKF mode run from YAML, the modes' counters reported; a wrong nested parameter, a mode that cannot be mixed and modes that accept different measurements are refused at the mode's own file:line:col.
set -u
TF=$1
DATA=$3
source "$(dirname "$0")/lib.sh"

P="$DATA/imm_ekf_ukf.yaml"  # line 23: the EKF mode, line 24: the UKF mode

expect_run "an IMM of an EKF CV mode and a UKF CA mode runs and meets its expect checks" 0 "4 passed, 0 failed" \
  -- "$TF" run "$P" --no-progress --out "$TMP/run"

# A mode's own counters reach the IMM's summary as <mode>.<counter>: over the radar's zenith
# the EKF mode drops azimuths (the same pipeline with the target passing overhead).
sed -e "s|initial_position: \[-5 km, 20 km, 3 km\]|initial_position: [-3 km, 0 km, 3 km]|" -e '/^expect:/,$d' "$P" > "$TMP/zenith.yaml"
expect_run "the EKF mode's azimuth_dropped counter is reported by the IMM" 0 \
  "ekf_cv\.azimuth_dropped +[1-9][0-9]*$" \
  -- "$TF" run "$TMP/zenith.yaml" --no-progress --out "$TMP/zenith"

# Each variant is the pipeline with line 24 (the UKF mode) changed; the errors point into that line.
variant() {
  sed "24s|.*|        - $1|" "$P" > "$TMP/$2.yaml"
}

variant "{ type: filter.ukf, motion: constant_acceleration, q_jerkk: 100 m2/s5 }" misspelt
expect_run "a misspelt key inside the second mode refused at its own line:col" 2 \
  "misspelt.yaml:24:62: node 'imm': unknown parameter 'q_jerkk' \(did you mean 'q_jerk'\?\)" \
  -- "$TF" validate "$TMP/misspelt.yaml"

variant "{ type: filter.ukf, motion: constant_acceleration, q_jerk: 100 m/s }" wrong_unit
expect_run "a wrong unit inside the second mode refused at the value's line:col" 2 \
  "wrong_unit.yaml:24:70: node 'imm': parameter 'q_jerk' has unit dimension m2/s5, but '100 m/s' is m/s" \
  -- "$TF" validate "$TMP/wrong_unit.yaml"

variant "{ type: filter.kalman, motion: constant_acceleration }" kalman
expect_run "a mode that measures in another frame refused at its type" 2 \
  "kalman.yaml:24:19: node 'imm': mode 2 \(filter.kalman\): it measures in another frame" \
  -- "$TF" validate "$TMP/kalman.yaml"

variant "{ type: filter.ukf, motion: constant_acceleration, range_rate: ignore }" range_rate
expect_run "modes that accept different measurements refused at the mode's range_rate" 2 \
  "range_rate.yaml:24:74: node 'imm': mode 2 \(filter.ukf\): range_rate ignore, but mode 1 has auto; every mode must accept the same measurements" \
  -- "$TF" validate "$TMP/range_rate.yaml"

variant "{ motion: constant_acceleration, q_jerk: 100 m2/s5 }" mixed
expect_run "records and components mixed in one list refused" 2 \
  "mixed.yaml:[0-9]+:[0-9]+: node 'imm': parameter 'modes': give every entry as a record or every entry as a component" \
  -- "$TF" validate "$TMP/mixed.yaml"

finish
