#!/usr/bin/env bash
# Purpose: the YAML loader ends every hostile file in exit 2 with file:line:col: recursive aliases, alias bombs, huge, deep, endless and multi-document files, odd keys, ids and names, big graphs.
set -u
source "$(dirname "$0")/lib.sh"

expect_run "an alias inside its own anchor (map) is exit 2, not a stack overflow" 2 \
  "recursive_alias_map.yaml:2:11: an alias refers to a node that contains it" -- "$TF" validate "$INPUTS/recursive_alias_map.yaml"
expect_run "a list that contains itself is exit 2 (run too)" 2 \
  "recursive_alias_list.yaml:3:8: an alias refers to a node that contains it" -- "$TF" run "$INPUTS/recursive_alias_list.yaml"
expect_run "... and in sweep" 2 "recursive alias" -- "$TF" sweep "$INPUTS/recursive_alias_list.yaml" --param a.b=1,2
base > "$TMP/ok.yaml"
expect_run "the same through --set" 2 "--set kf.q:1:1: an alias refers to a node that contains it" \
  -- "$TF" validate "$TMP/ok.yaml" --set 'kf.q=&a [*a]'
expect_run "a 512-byte alias bomb stops at the expansion limit" 2 \
  "billion_laughs.yaml:[0-9]+:[0-9]+: the YAML expands to more than 250000 values" -- "$TF" validate "$INPUTS/billion_laughs.yaml"
expect_run "a second YAML document is refused, not ignored" 2 \
  "second_document.yaml:3:1: a second YAML document" -- "$TF" validate "$INPUTS/second_document.yaml"
expect_run "input on which yaml-cpp's LoadAll loops forever is exit 2, not a hang" 2 \
  "yaml_cpp_loop.yaml:[0-9]+:[0-9]+: YAML syntax error" -- timeout 20 "$TF" validate "$INPUTS/yaml_cpp_loop.yaml"
expect_run "a lone comma too" 2 "YAML syntax error" -- timeout 20 "$TF" validate --set "kf.q=," "$INPUTS/../../cli/data/determinism.yaml"
expect_run "validate /dev/zero stops at the size limit" 2 "'/dev/zero' is larger than 2048 KiB" -- "$TF" validate /dev/zero
{ base; printf '# %*s\n' 3000000 x; } > "$TMP/big.yaml"
expect_run "a 3 MB file is refused before it is parsed" 2 "big.yaml' is larger than 2048 KiB" -- "$TF" validate "$TMP/big.yaml"
expect_run "a folder is not a pipeline" 2 "is a folder, not a pipeline file" -- "$TF" validate "$TMP"
python3 -c "print('pipeline: {name: deep}\nnodes: ' + '[' * 100 + ']' * 100)" > "$TMP/deep.yaml"
expect_run "100 levels of nesting are refused" 2 "deep.yaml:[0-9]+:[0-9]+: the YAML nests deeper than 64 levels" -- "$TF" validate "$TMP/deep.yaml"
python3 -c "print('pipeline: {name: deeper}\nnodes: ' + '[' * 5000 + ']' * 5000)" > "$TMP/deeper.yaml"
expect_run "5000 levels end in exit 2 (the parser's own limit), not a crash" 2 "deeper.yaml:[0-9]+:[0-9]+: YAML" -- "$TF" validate "$TMP/deeper.yaml"
printf 'pipeline: {name: k}\nnodes:\n  - {id: a, type: sim.trajectory, ? [x, y] : 1}\n' > "$TMP/complex_key.yaml"
expect_run "a list as a map key is refused" 2 "complex_key.yaml:3:[0-9]+: a map key must be a plain name" -- "$TF" validate "$TMP/complex_key.yaml"
expect_run "a node id that is not UTF-8 (or not ASCII) is refused at its line" 2 \
  "non_utf8_id.yaml:4:[0-9]+: node id 'k\?\?f' must be 1 to 100 ASCII letters" -- "$TF" validate "$INPUTS/non_utf8_id.yaml"
base | sed 's/name: hostile/name: ..\/..\/escape/' > "$TMP/name.yaml"
expect_run "a pipeline name that would leave out/ is refused" 2 "name.yaml:1:19: name '../../escape' must be" -- "$TF" validate "$TMP/name.yaml"
base | sed 's/seed: 1/seed: 18446744073709551615/' > "$TMP/seed_max.yaml"
expect_run "a 64-bit seed in the YAML is accepted" 0 "ok" -- "$TF" validate "$TMP/seed_max.yaml"
base | sed 's/seed: 1/seed: 18446744073709551616/' > "$TMP/seed_over.yaml"
expect_run "a seed beyond 64 bits is refused at its line" 2 "seed_over.yaml:1:34: seed must be a whole number from 0 to 18446744073709551615" \
  -- "$TF" validate "$TMP/seed_over.yaml"
base | sed 's/runs: 2/runs: -1/' > "$TMP/runs_neg.yaml"
expect_run "runs: -1 is refused, not wrapped" 2 "runs_neg.yaml:1:[0-9]+: runs must be a whole number" -- "$TF" validate "$TMP/runs_neg.yaml"

# 10 001 nodes: refused with the limit; 10 000 (a chain of converters) validate in linear time
# (the former quadratic build took minutes at this size; the ctest timeout is the guard).
python3 - "$TMP" <<'PY'
import sys
d = sys.argv[1]
head = "pipeline: {name: many, runs: 1}\nnodes:\n  - {id: truth, type: sim.trajectory, params: {rate: 1 Hz, initial_position: [6000, 8000, 1000], initial_velocity: [1, 0, 0], segments: [{type: constant_velocity, duration: 3 s}]}}\n  - {id: r0, type: sim.radar, input: truth}\n"
chain = "".join(f"  - {{id: c{i}, type: convert.classical, input: {'r0' if i == 0 else 'c%d' % (i - 1)}}}\n" for i in range(9998))
open(d + "/many.yaml", "w").write(head + chain)
chain2 = "".join(f"  - {{id: c{i}, type: convert.classical, input: {'r0' if i == 0 else 'c%d' % (i - 1)}}}\n" for i in range(9999))
open(d + "/too_many.yaml", "w").write(head + chain2)
PY
expect_run "10 000 nodes validate" 0 "ok \(10000 nodes" -- "$TF" validate "$TMP/many.yaml"
expect_run "10 001 nodes are refused with the limit" 2 "too_many.yaml:3:3: 'nodes' lists 10001 nodes; at most 10000" -- "$TF" validate "$TMP/too_many.yaml"
finish
