#!/usr/bin/env bash
# Purpose: docs/plugin-guide.md section 1 word for word: the lean SDK build (tests and benchmarks off) of a copy of this tree, installed, then the installed example plugin copied, built, tested and run (issue 26).
# Usage: plugin_guide.sh <repo root>
# The guide's commands are the ```sh blocks marked <!-- run by tests/cli/plugin_guide.sh -->; they
# run as written, in a copy of the tree, with HOME a fresh folder. ccache (its base folder the
# copy's root, as setup.sh sets it to the tree's root) makes the compiles of the suite's own Release build hits, so this is mostly
# linking.
set -u
repo=${1:?usage: plugin_guide.sh <repo root>}
guide="$repo/docs/plugin-guide.md"
if [ -n "${TRACKFLOW_SANITIZE:-}" ]; then
  # The guide's build is a plain Release build: under `setup.sh sanitize` nothing of it is in the
  # compiler cache, and it would be a second cold build of the whole tree.
  echo "SKIPPED: under setup.sh sanitize (the guide's plain Release build would be a second cold build)"
  exit 77
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/trackflow-guide.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
tmp=$(cd "$tmp" && pwd -P)
log="$tmp/log"
fail() {
  echo "FAIL: $*" >&2
  [ -s "$log" ] && tail -n 60 "$log" >&2
  exit 1
}
unset TRACKFLOW_PLUGIN_PATH

# The marked blocks, in order.
awk '/<!-- run by tests\/cli\/plugin_guide.sh -->/ { marked = 1; next }
     marked { if ($0 == "```sh") { inside = 1; blocks++ } marked = 0; next }
     inside && /^```$/ { inside = 0; next }
     inside { print }
     END { if (blocks != 2) { print "expected 2 marked sh blocks, found " blocks > "/dev/stderr"; exit 1 } }' \
  "$guide" > "$tmp/commands.sh" || fail "docs/plugin-guide.md: the commands to run are two sh code blocks, each after a <!-- run by tests/cli/plugin_guide.sh --> line"
echo "== the guide's commands:"
sed 's/^/   /' "$tmp/commands.sh"

mkdir -p "$tmp/trackflow" "$tmp/home"
tar -C "$repo" --exclude='./build*' --exclude=./.git -cf - . | tar -C "$tmp/trackflow" -xf - ||
  fail "copying the tree failed"
echo "== running them in a copy of the tree, HOME=$tmp/home"
(
  export HOME="$tmp/home" CCACHE_BASEDIR="$tmp/trackflow"
  cd "$tmp/trackflow" || exit 1
  set -e -x
  source "$tmp/commands.sh"
) > "$log" 2>&1 || fail "a command of the guide failed (its output, last lines, below)"
grep -q 'passed, 0 failed\|tests passed' "$log" || fail "the example's tests did not report passing"
grep -Eq '^  pass ' "$log" || fail "trackflow run alpha_beta.yaml printed no passing expect check"
echo "   ok: every command succeeded; the example's tests passed and its pipeline's expect block passed"

# Lean means lean: the build the guide asks for has no test or benchmark executables.
extra=$(ninja -C "$tmp/trackflow/build-sdk" -t targets all 2>/dev/null | grep -Eo '^[^:]*(bin/trackflow-bench[^:]*|/test_[a-z0-9_]+)(:| )' | head -5)
[ -z "$extra" ] || fail "the guide's SDK build still builds tests or benchmarks: $extra"
steps=$(ninja -C "$tmp/trackflow/build-sdk" -t commands all | wc -l)
echo "   ok: the SDK build has no test or benchmark targets ($steps build commands)"

# What the guide says is installed, is.
prefix="$tmp/home/trackflow"
for f in include/trackflow/estimator.hpp include/trackflow/testing/plugin_fixture.hpp bin/trackflow \
         lib/cmake/trackflow/trackflowConfig.cmake share/doc/trackflow/README.md \
         share/doc/trackflow/docs/plugin-guide.md share/doc/trackflow/examples/alpha_beta_plugin/CMakeLists.txt; do
  [ -e "$prefix/$f" ] || fail "the install has no $f (docs/plugin-guide.md section 1 says it does)"
done
ls "$prefix"/lib*/libtrackflow_sdk.so > /dev/null 2>&1 || fail "the install has no libtrackflow_sdk.so"
echo "   ok: the install holds the headers, the installed fixture, the libraries, the CMake package, the docs and the example"
echo "PASS: docs/plugin-guide.md section 1, word for word"
