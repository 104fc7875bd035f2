#!/usr/bin/env bash
# Purpose: every Catch2 test case is one ctest entry. For each Catch2 binary, the test cases it lists
# (--list-test-names-only) must be exactly the ctest entries named "<prefix><case>" in the build
# folder (ctest -N): a name that catch_discover_tests mangles (`;`, unbalanced `]`, ...) shows up as
# a missing case and as unexpected entries, and the check fails naming both. Entry names longer than
# 70 characters fail too: ctest pads every output line to the longest name.
# Usage: catch_count.sh <ctest> <build dir> <manifest>
#   manifest: one line per Catch2 binary: <binary path><TAB><ctest name prefix>
set -u

ctest=${1:?usage: catch_count.sh <ctest> <build dir> <manifest>}
build=${2:?usage: catch_count.sh <ctest> <build dir> <manifest>}
manifest=${3:?usage: catch_count.sh <ctest> <build dir> <manifest>}

tmp=$(mktemp -d "${TMPDIR:-/tmp}/trackflow-catch-count.XXXXXX") || { echo "FAIL: mktemp -d failed" >&2; exit 1; }
trap 'rm -rf "$tmp"' EXIT
export LC_ALL=C  # byte order for sort/comm, whatever the names contain

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

max_name=70  # characters of "<prefix><case>"

[ -s "$manifest" ] || fail "no Catch2 binaries recorded in $manifest"

# Every ctest entry of the build folder, by name. ctest -N would rewrite <build>/Testing/Temporary/
# LastTest.log, which the ctest running this check is writing: list from a copy of the
# CTestTestfile.cmake tree instead (it includes the discovered Catch2 entries by absolute path).
[ -f "$build/CTestTestfile.cmake" ] || fail "no CTestTestfile.cmake in $build"
(cd "$build" && find . -name CTestTestfile.cmake -not -path './Testing/*') | while IFS= read -r f; do
  mkdir -p "$tmp/tree/$(dirname "$f")" && cp "$build/$f" "$tmp/tree/$f"
done
"$ctest" --test-dir "$tmp/tree" -N >"$tmp/ctest.log" 2>&1 || {
  cat "$tmp/ctest.log" >&2
  fail "ctest -N over the test files of $build failed"
}
sed -n 's/^ *Test *#[0-9]*: //p' "$tmp/ctest.log" >"$tmp/entries"
total_entries=$(grep -c '' "$tmp/entries")

binaries=0 cases=0 matched=0 problems=0
while IFS=$'\t' read -r binary prefix; do
  [ -n "$binary" ] || continue
  binaries=$((binaries + 1))
  name=$(basename "$binary")
  [ -x "$binary" ] || { echo "FAIL: $name: no executable at $binary (not built?)" >&2; problems=$((problems + 1)); continue; }
  "$binary" --list-test-names-only >"$tmp/raw" 2>"$tmp/err"
  rc=$?
  if [ -s "$tmp/err" ]; then
    cat "$tmp/err" >&2
    echo "FAIL: $name --list-test-names-only wrote to stderr" >&2
    problems=$((problems + 1))
    continue
  fi
  # Expected entries: the prefix and each listed name (Catch2 quotes names that start with '#').
  sed -e '/^$/d' -e 's/^"\(#.*\)"$/\1/' "$tmp/raw" | awk -v p="$prefix" '{ print p $0 }' | sort >"$tmp/expected"
  awk -v p="$prefix" 'index($0, p) == 1' "$tmp/entries" | sort >"$tmp/actual"
  n_listed=$(grep -c '' "$tmp/expected")
  # Catch2 v2 exits with the number of test cases listed (at most 255): anything else is a crash.
  if [ "$rc" -ne "$((n_listed < 255 ? n_listed : 255))" ]; then
    echo "FAIL: $name --list-test-names-only exited $rc after listing $n_listed test case(s)" >&2
    problems=$((problems + 1))
    continue
  fi
  n_entries=$(grep -c '' "$tmp/actual")
  comm -23 "$tmp/expected" "$tmp/actual" >"$tmp/missing"
  comm -13 "$tmp/expected" "$tmp/actual" >"$tmp/unexpected"
  n_missing=$(grep -c '' "$tmp/missing")
  n_unexpected=$(grep -c '' "$tmp/unexpected")
  cases=$((cases + n_listed))
  matched=$((matched + n_listed - n_missing))
  # ctest pads every line of its output to the longest test name: keep them short.
  awk -v max="$max_name" 'length($0) > max' "$tmp/expected" >"$tmp/long"
  if [ -s "$tmp/long" ]; then
    {
      echo "FAIL: $name: ctest entries longer than $max_name characters (shorten the test case names):"
      sed 's/^/    /' "$tmp/long"
    } >&2
    problems=$((problems + 1))
  fi
  if [ "$n_listed" -eq 0 ]; then
    echo "FAIL: $name lists no test cases" >&2
    problems=$((problems + 1))
  elif [ "$n_missing" -ne 0 ] || [ "$n_unexpected" -ne 0 ] || [ "$n_listed" -ne "$n_entries" ]; then
    {
      echo "FAIL: $name lists $n_listed test case(s) but ctest has $n_entries entr(ies) named '$prefix...'"
      if [ "$n_missing" -ne 0 ]; then
        echo "  $n_missing case(s) without their own ctest entry (rename them: no ';' ',' '[' ']' '\\'):"
        sed 's/^/    /' "$tmp/missing"
      fi
      if [ "$n_unexpected" -ne 0 ]; then
        echo "  $n_unexpected ctest entr(ies) that are not a test case of $name (they run nothing):"
        sed 's/^/    /' "$tmp/unexpected"
      fi
    } >&2
    problems=$((problems + 1))
  else
    [ -s "$tmp/long" ] || echo "ok: $name: $n_listed test cases, $n_entries ctest entries '$prefix...'"
  fi
done <"$manifest"

[ "$binaries" -gt 0 ] || fail "no Catch2 binaries recorded in $manifest"
echo "$binaries Catch2 binaries: $cases test cases listed, $matched with their own ctest entry ($total_entries ctest entries in all)"
[ "$problems" -eq 0 ] || fail "$problems problem(s) in $binaries Catch2 binaries (see above)"
echo "PASS: every Catch2 test case is exactly one ctest entry"
