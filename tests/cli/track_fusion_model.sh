#!/usr/bin/env bash
# Purpose: filter.track_fusion predicts with the transition model its inputs name (issue 20): the two-station pipeline's fusion nodes give none and validate; a model of their own that differs from the inputs', or inputs that differ, are refused before the run at the fusion node's line, naming both models.
set -u
TF=$1
ROOT=$4
source "$(dirname "$0")/lib.sh"

P="$ROOT/pipelines/two_station_launch.yaml"  # line 92: the node 'information'

expect_run "fusion nodes without motion parameters take their inputs' model" 0 "" \
  -- "$TF" validate "$P"

expect_run "a fusion model other than the inputs' refused at the node, naming both" 2 \
  "two_station_launch.yaml:92:[0-9]+: node 'information': .*input 'naro_ekf' \(filter.ekf\) predicts with constant_acceleration, q_jerk 1 m2/s5, but this node's parameters give constant_acceleration, q_jerk 100 m2/s5" \
  -- "$TF" validate "$P" --set information.motion=constant_acceleration --set information.q_jerk=100

expect_run "inputs that predict differently refused at the fusion node, naming both inputs" 2 \
  "two_station_launch.yaml:88:[0-9]+: node 'ci': .*input 'jeju_ekf' \(filter.ekf\) predicts with constant_acceleration, q_jerk 1 m2/s5, but input 'naro_ekf' with constant_acceleration, q_jerk 100 m2/s5" \
  -- "$TF" validate "$P" --set naro_ekf.q_jerk=100

finish
