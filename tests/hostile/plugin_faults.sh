#!/usr/bin/env bash
# Purpose: a plugin that throws, crashes or aborts is reported with its file, the node and the run (exit 3), a data error keeps exit 2; a faulty registration is a named load problem.
set -u
source "$(dirname "$0")/lib.sh"

MIS="$HOSTILE/misbehave"
SO="$MIS/tfplugin_test_misbehave.so"
[ -f "$SO" ] || fail "the test plugin $SO is not built"
# The misbehaving node sits between the converter and the filter; it acts at the 4th measurement
# of run 1 (of 3), on whichever thread runs it.
pipeline() {
  base | sed 's/runs: 2/runs: 3/; s/input: cm$/input: bad/'
  printf '  - id: bad\n    type: test.misbehave\n    input: cm\n    params: { what: %s, run: 1 }\n' "$1"
}
for what in throw_std throw_int throw_data segfault stack_overflow abort none; do pipeline $what > "$TMP/$what.yaml"; done
run() { "$TF" run "$TMP/$1.yaml" --plugin-path "$MIS" --out "$TMP/out" --no-progress "${@:2}"; }
who="node 'bad' \(test.misbehave from $SO\)"

expect_run "the pipeline runs when the plugin behaves" 0 "measurements processed" -- run none
expect_run "a std::exception is an internal error naming plugin file, node and run" 3 \
  "internal error: $who during run 1 threw std::out_of_range: index 7 out of range" -- run throw_std
expect_run "... also on 2 threads" 3 "internal error: $who during run 1 threw std::out_of_range" -- run throw_std --threads 2
expect_run "an exception that is not a std::exception does not abort the host" 3 \
  "internal error: $who during run 1 threw an exception that is not a std::exception" -- run throw_int --threads 2
expect_run "a DataError stays a data error (exit 2), with the run and the node" 2 \
  "data error: run 1: $who: a deliberate data error" -- run throw_data
expect_run "a segmentation fault prints the node being executed and the run" 3 \
  "internal error: crash \(SIGSEGV, invalid memory access\) in $who during run 1" -- run segfault
expect_run "... on a worker thread too" 3 "crash \(SIGSEGV, invalid memory access\) in $who during run 1" -- run segfault --threads 2
expect_run "a stack overflow in a plugin is reported, not a silent death" 3 \
  "crash \(SIGSEGV, invalid memory access\) in $who during run 1" -- run stack_overflow --threads 2
expect_run "... also on the main thread (one thread runs there)" 3 "crash \(SIGSEGV, invalid memory access\) in $who during run 1" -- run stack_overflow
expect_run "an abort in a plugin is reported" 3 "crash \(SIGABRT, abort\) in $who during run 1" -- run abort

expect_run "validate never runs the plugin's item code" 0 "ok" -- "$TF" validate "$TMP/segfault.yaml" --plugin-path "$MIS"
expect_run "a registration that throws a non-std exception is a named load problem" 2 \
  "tfplugin_test_bad_register.so: register: registration threw an exception that is not a std::exception" \
  -- "$TF" plugins --plugin-path "$HOSTILE/bad_register"
expect_run "... and the other plugins still work" 0 "measurements processed" \
  -- "$TF" run "$TMP/none.yaml" --plugin-path "$MIS" --plugin-path "$HOSTILE/bad_register" --out "$TMP/out"
# The same for a plugin's merge(), which runs on the aggregating instance, in run order: the
# merge of run 7 fails, whichever thread ran it (test.fail_run, from the test-plugins folder).
FAIL_YAML="$INPUTS/../../cli/data/mpi_fail.yaml"
fail_run() { "$TF" run "$FAIL_YAML" --plugin-path "$PLUGINS/../test-plugins" --out "$TMP/out" --no-progress "$@"; }
boom="node 'boom' \(test.fail_run from [^)]*tfplugin_test_fail_run.so\)"
expect_run "a DataError in merge() names the run and the node" 2 "data error: run 7: $boom: test.fail_run: deliberate failure" \
  -- fail_run --threads 2 --set boom.during=merge
expect_run "a std::exception in merge() is an internal error naming the node and run" 3 \
  "internal error: $boom during run 7 threw std::logic_error: test.fail_run: deliberate bug" \
  -- fail_run --threads 2 --set boom.during=merge --set boom.kind=bug
finish
