#!/usr/bin/env bash
# Purpose: component-valued parameters (Component, ComponentList): a nested {type: ..., <params>} map is validated against its own type's declaration, errors at the nested key's own file:line:col.
set -u
TF=$1
PLUGINS=$2
TEST_PLUGINS="$PLUGINS/../test-plugins"
source "$(dirname "$0")/lib.sh"

# nested PRIMARY MODE2: the base pipeline's filter into test.nested (line 23: primary, line 26: 2nd mode).
nested() {
  truth_radar nested 1 1 5
  classical_kalman
  cat <<YAML
  - id: nest
    type: test.nested
    input: kf
    params:
      primary: $1
      modes:
        - { type: filter.ekf, motion: constant_velocity, q: 1 m2/s3 }
        - $2
YAML
}

nested "{ type: filter.ekf, q: 2 m2/s3 }" "{ type: filter.ukf }" > "$TMP/ok.yaml"
expect_run "valid nested component and component list accepted" 0 "" \
  -- "$TF" validate "$TMP/ok.yaml" --plugin-path "$TEST_PLUGINS"

nested "{ type: filter.ekf, qq: 2 m2/s3 }" "{ type: filter.ukf }" > "$TMP/unknown_key.yaml"
expect_run "unknown nested key refused at its own line:col, with a suggestion" 2 \
  "unknown_key.yaml:23:36: node 'nest': unknown parameter 'qq' \(did you mean 'q'\?\); known: motion, q," \
  -- "$TF" validate "$TMP/unknown_key.yaml" --plugin-path "$TEST_PLUGINS"

nested "{ type: filter.ekf }" "{ type: filter.ukf, q: 2 m/s }" > "$TMP/wrong_unit.yaml"
expect_run "wrong nested unit in a list entry refused at the value's line:col" 2 \
  "wrong_unit.yaml:26:34: node 'nest': parameter 'q' has unit dimension m2/s3, but '2 m/s' is m/s" \
  -- "$TF" validate "$TMP/wrong_unit.yaml" --plugin-path "$TEST_PLUGINS"

nested "{ type: filter.ekff }" "{ type: filter.ukf }" > "$TMP/unknown_type.yaml"
expect_run "unknown nested type refused with the accepted types" 2 \
  "unknown_type.yaml:23:24: node 'nest': parameter 'primary': unknown type 'filter.ekff' \(did you mean 'filter.ekf'\?\); accepted \(filter\): .*filter.ekf.*filter.ukf" \
  -- "$TF" validate "$TMP/unknown_type.yaml" --plugin-path "$TEST_PLUGINS"

nested "{ type: filter.ekf }" "{ type: sink.metrics }" > "$TMP/wrong_kind.yaml"
expect_run "a type of another kind refused" 2 \
  "wrong_kind.yaml:26:19: node 'nest': parameter 'modes': type 'sink.metrics' is not accepted here; accepted \(filter, type filter.\*\)" \
  -- "$TF" validate "$TMP/wrong_kind.yaml" --plugin-path "$TEST_PLUGINS"

expect_run "describe prints the accepted kind" 0 \
  "primary +component \{type: filter\} +required.*modes +list of components \{type: filter, type filter.\*\}" \
  -- bash -c "'$TF' describe test.nested --plugin-path '$TEST_PLUGINS' | tr '\n' ' '"

finish
