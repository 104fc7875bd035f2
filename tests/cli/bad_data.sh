#!/usr/bin/env bash
# Purpose: CLI test of bad recorded data: each bad-row case stops a run with exit 2 naming FILE:LINE, or is skipped and counted.
# Usage: bad_data.sh <trackflow cli> <plugin dir> <tests/cli/data dir> <repo root>
set -u

if [ $# -lt 4 ]; then
  echo "usage: $0 <trackflow cli> <plugin dir> <tests/cli/data dir> <repo root>" >&2
  exit 2
fi
# Absolute paths: the checks run from a temp folder.
TF=$(realpath -- "$1") || exit 1
PLUGINS=$(realpath -- "$2") || exit 1
DATA=$(realpath -- "$3") || exit 1
# $4 (repo root) is part of the common CLI-test signature; nothing here needs it.

[ -x "$TF" ] || { echo "FAIL: trackflow CLI '$TF' is not an executable" >&2; exit 1; }
[ -d "$DATA" ] || { echo "FAIL: data folder '$DATA' does not exist" >&2; exit 1; }

WORK=$(mktemp -d "${TMPDIR:-/tmp}/trackflow_bad_data.XXXXXX") || { echo "FAIL: cannot create a temp dir" >&2; exit 1; }
trap 'rm -rf "$WORK"' EXIT
# Run from an unrelated folder: a CSV path in a pipeline must resolve next to the pipeline file.
cd "$WORK" || exit 1

STDOUT=$WORK/stdout
STDERR=$WORK/stderr
RC=0
CHECKS=0

fail() {
  echo "FAIL: $*" >&2
  echo "--- exit code: $RC" >&2
  echo "--- stdout:" >&2
  cat "$STDOUT" >&2
  echo "--- stderr:" >&2
  cat "$STDERR" >&2
  exit 1
}

# trackflow <command> <pipeline name> [args...]: runs the CLI on $DATA/<name>.yaml, keeps the exit code in RC.
trackflow() {
  local cmd=$1 name=$2
  shift 2
  local extra=()
  [ "$cmd" = run ] && extra=(--no-progress --out "$WORK/out/$name")
  "$TF" "$cmd" "$DATA/$name.yaml" "${extra[@]}" --no-default-plugins --plugin-path "$PLUGINS" "$@" \
    >"$STDOUT" 2>"$STDERR"
  RC=$?
}

expect_exit() {
  [ "$RC" -ge 128 ] && fail "$2: trackflow crashed (signal $((RC - 128))); expected exit code $1"
  [ "$RC" -eq "$1" ] || fail "$2: expected exit code $1, got $RC"
}

expect_stderr() {
  grep -qF -- "$1" "$STDERR" || fail "$2: stderr does not contain '$1'"
}

expect_stdout() {
  grep -qF -- "$1" "$STDOUT" || fail "$2: stdout does not contain '$1'"
}

# The summary reports the node's skips ("skipped: N") and its skipped_rows metric.
expect_skip_count() {
  local count=$1 what=$2
  grep -qE "^ +skipped: $count\$" "$STDOUT" || fail "$what: stdout does not report 'skipped: $count'"
  grep -qE "^ +skipped_rows +$count\$" "$STDOUT" || fail "$what: stdout does not report 'skipped_rows $count'"
}

check() {
  CHECKS=$((CHECKS + 1))
  echo "check $CHECKS: $*"
}

# name | bad line | what the message says
CASES=(
  "bad_nonnumeric|4|not a number (column range, value '12x3')"
  "bad_nan|3|NaN or infinite value (column azimuth, value 'nan')"
  "bad_infinite|5|NaN or infinite value (column elevation, value '-inf')"
  "bad_fields|3|wrong number of fields: expected 4"
  "bad_negative_range|4|negative range (column range, value '-0.02')"
  "bad_time_backwards|5|time goes backwards: earlier than 2 on line 4 (column time, value '1.5')"
  "bad_truncated|5|truncated last line: expected 4 fields"
  "bad_no_newline|4|the last line looks truncated (no newline at the end of the file)"
)

for c in "${CASES[@]}"; do
  IFS='|' read -r name line says <<<"$c"
  where="$name.csv:$line:"

  check "$name: on_bad_row error (default) exits 2 and names $where"
  trackflow run "$name"
  expect_exit 2 "$name (error)"
  expect_stderr "$where" "$name (error)"
  expect_stderr "$says" "$name (error)"
  expect_stderr "node 'radar'" "$name (error)"

  check "$name: trackflow validate finds the same bad row"
  trackflow validate "$name"
  expect_exit 2 "$name (validate)"
  expect_stderr "$where" "$name (validate)"

  check "$name: --set radar.on_bad_row=skip exits 0 and reports 1 skipped row at $where"
  trackflow run "$name" --set radar.on_bad_row=skip
  expect_exit 0 "$name (skip)"
  expect_skip_count 1 "$name (skip)"
  expect_stdout "$where" "$name (skip)"
done

check "bad_mixed_skip: pipeline-wide on_bad_row: skip, 3 runs on 2 threads, CRLF; 3 bad rows counted once"
trackflow run bad_mixed_skip --threads 2
expect_exit 0 "bad_mixed_skip"
expect_skip_count 3 "bad_mixed_skip"
for line in 3 5 7; do expect_stdout "bad_mixed_skip.csv:$line:" "bad_mixed_skip"; done
grep -qE "^ +rows +7\$" "$STDOUT" || fail "bad_mixed_skip: stdout does not report 'rows 7'"

check "bad_mixed_skip: the node's own on_bad_row: error overrides the pipeline-wide skip"
trackflow run bad_mixed_skip --set radar.on_bad_row=error
expect_exit 2 "bad_mixed_skip (node error)"
expect_stderr "bad_mixed_skip.csv:3:" "bad_mixed_skip (node error)"

for name in bad_empty bad_header_only; do
  for mode in error skip; do
    check "$name: exits 2 with on_bad_row $mode (an unusable file is never skipped)"
    trackflow run "$name" --set radar.on_bad_row=$mode
    expect_exit 2 "$name ($mode)"
    expect_stderr "$name.csv" "$name ($mode)"
  done
done
expect_stderr "bad_header_only.csv:1: the file has a header but no data rows" "bad_header_only"

check "bad_missing_column: exits 2 naming the file, the header line, the columns and the close name"
trackflow run bad_missing_column --set radar.on_bad_row=skip
expect_exit 2 "bad_missing_column"
expect_stderr "bad_missing_column.csv:1: no column 'range' (range_column)" "bad_missing_column"
expect_stderr "did you mean 'rnage'" "bad_missing_column"
expect_stderr "'time', 'rnage', 'azimuth', 'elevation'" "bad_missing_column"

check "a missing CSV file is a configuration error pointing at the path parameter"
trackflow run bad_nonnumeric --set radar.path=no_such_file.csv
expect_exit 2 "missing file"
expect_stderr "parameter 'path'" "missing file"
expect_stderr "no_such_file.csv" "missing file"
# The message gives the resolved, absolute path and how a relative one was resolved (issue 26).
grep -Eq "cannot open '/[^']*/no_such_file\.csv': No such file or directory \(path 'no_such_file\.csv' is read relative to the working directory\)" "$STDERR" ||
  fail "missing file: stderr does not give the resolved path and how it was resolved: $(cat "$STDERR")"

echo "ok: $CHECKS checks passed"
exit 0
