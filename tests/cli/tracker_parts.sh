#!/usr/bin/env bash
# Purpose: a tracker part (assoc.*, init.*, delete.*) given as a node of the graph is refused at its type's line, saying where it belongs; `describe` shows tracker.multi's component parameters and the parts' kinds.
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

finish
