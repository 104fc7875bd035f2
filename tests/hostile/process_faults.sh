#!/usr/bin/env bash
# Purpose: plugin code that ends the process (exit(), quick_exit) or crashes on two threads at the same moment is reported as exit 3 naming the node and run, every time; a ConfigError thrown inside a run names the node and the run (issue 27).
set -u
source "$(dirname "$0")/lib.sh"

MIS="$HOSTILE/misbehave"
# misbehave WHAT RUN [TOGETHER]: the base pipeline with test.misbehave (node bad) between cm and kf, 4 runs.
misbehave() {
  base | sed 's/runs: 2/runs: 4/; s/input: cm$/input: bad/'
  printf '  - { id: bad, type: test.misbehave, input: cm, params: { what: %s, run: %s, together: %s } }\n' "$1" "$2" "${3:-0}"
}

# exit(0) inside a run: before, trackflow exited 0 with no summary and no outputs.
misbehave exit0 1 > "$TMP/exit0.yaml"
expect_run "exit(0) in a plugin during a run is exit 3 naming the node and the run" 3 \
  "internal error: exit\(\) called .* in node 'bad' \(test.misbehave from .*\) during run 1; a bug in that plugin" \
  -- "$TF" run "$TMP/exit0.yaml" --plugin-path "$MIS" --out "$TMP/o"
expect_run "... with --threads 2 too" 3 "exit\(\) called .* in node 'bad' .* during run 1" \
  -- "$TF" run "$TMP/exit0.yaml" --plugin-path "$MIS" --out "$TMP/o" --threads 2
misbehave quick_exit0 2 > "$TMP/qexit.yaml"
expect_run "quick_exit(0) in a plugin during a run is exit 3 naming the node and the run" 3 \
  "exit\(\) called .* in node 'bad' .* during run 2" -- "$TF" run "$TMP/qexit.yaml" --plugin-path "$MIS" --out "$TMP/o"
"$TF" run "$TMP/exit0.yaml" --plugin-path "$MIS" --out "$TMP/o" > "$TMP/exit0.out" 2>&1
expect_no "... and prints no summary as if it had finished" "measurements processed" "$TMP/exit0.out"
# The engine's own exit at the end stays a success.
misbehave none 0 > "$TMP/none.yaml"
expect_run "a run without misbehaviour still exits 0" 0 "measurements processed" \
  -- "$TF" run "$TMP/none.yaml" --plugin-path "$MIS" --out "$TMP/o"

# A ConfigError thrown by a plugin inside a run: before, neither node nor run was named.
misbehave throw_config 2 > "$TMP/config.yaml"
expect_run "a ConfigError thrown in a run names the run and the node" 2 \
  "error: run 2: node 'bad' \(test.misbehave from .*\): a deliberate configuration error" \
  -- "$TF" run "$TMP/config.yaml" --plugin-path "$MIS" --out "$TMP/o"
expect_run "... with --threads 2 too" 2 "run 2: node 'bad' .*a deliberate configuration error" \
  -- "$TF" run "$TMP/config.yaml" --plugin-path "$MIS" --out "$TMP/o" --threads 2

# Two threads crash at the same moment (both wait for each other at measurement 3, then crash):
# before, SA_RESETHAND let the second one kill trackflow by its signal in about half the runs.
for what in segfault abort; do
  misbehave "$what" -1 2 > "$TMP/both_$what.yaml"
  n=$([ "$what" = segfault ] && echo 100 || echo 30)
  bad=0 other=""
  for i in $(seq 1 "$n"); do
    "$TF" run "$TMP/both_$what.yaml" --plugin-path "$MIS" --out "$TMP/o" --threads 2 > "$TMP/both.out" 2>&1
    rc=$?
    if [ "$rc" -ne 3 ] || [ "$(grep -c 'internal error: crash' "$TMP/both.out")" -ne 1 ]; then
      bad=$((bad + 1))
      other="$other $rc"
    fi
  done
  [ "$bad" -eq 0 ] || fail "two threads that $what at once: $bad of $n runs not exit 3 with one message (exit codes:$other)"
  checks=$((checks + 1))
  echo "ok: two threads that $what at once: exit 3 with one message in $n of $n runs"
done
expect_run "... the message names the node and a run" 3 "crash \(SIGSEGV, invalid memory access\) in node 'bad' .* during run [01]" \
  -- "$TF" run "$TMP/both_segfault.yaml" --plugin-path "$MIS" --out "$TMP/o" --threads 2
finish
