#!/usr/bin/env bash
# Purpose: a plugin author's path end to end: install trackflow, build examples/alpha_beta_plugin against the install, run it.
# Usage: sdk_install.sh <trackflow build dir> <repo root>
set -u

build_dir=${1:?usage: sdk_install.sh <trackflow build dir> <repo root>}
repo=${2:?usage: sdk_install.sh <trackflow build dir> <repo root>}
example="$repo/examples/alpha_beta_plugin"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/trackflow-sdk.XXXXXX") || { echo "FAIL: mktemp -d failed" >&2; exit 1; }
trap 'rm -rf "$tmp"' EXIT
tmp=$(cd "$tmp" && pwd -P)  # the CLI reports plugin paths from /proc/self/exe, i.e. with symlinks resolved
# Only what the test passes explicitly may be searched for plugins.
unset TRACKFLOW_PLUGIN_PATH
prefix="$tmp/prefix"
plugin_build="$tmp/build"
log="$tmp/log"

step() { echo "== $*"; }
ok() { echo "   ok: $*"; }
fail() {
  echo "FAIL: $*" >&2
  if [ -s "$log" ]; then
    echo "---- output of the failing step (last 60 lines) ----" >&2
    tail -n 60 "$log" >&2
  fi
  exit 1
}

step "install $build_dir into a fresh prefix"
cmake --install "$build_dir" --prefix "$prefix" >"$log" 2>&1 || fail "cmake --install $build_dir failed"
tf="$prefix/bin/trackflow"
[ -x "$tf" ] || fail "no executable at $tf after install"
ok "installed $tf"

# The installed CLI searches <exe dir>/../lib/trackflow/plugins (and the configured
# <libdir>/trackflow/plugins) by default: every installed in-tree plugin must be found there
# without any --plugin-path or TRACKFLOW_PLUGIN_PATH.
installed=$(cd "$prefix" && find . -name 'tfplugin_*.so' | sed 's|^\./||' | sort)
[ -n "$installed" ] || fail "the install contains no tfplugin_*.so at all"
in_tree_count=$(echo "$installed" | wc -l)
install_dirs=$(echo "$installed" | xargs -n 1 dirname | sort -u | tr '\n' ' ' | sed 's/ $//')
ok "$in_tree_count in-tree plugin(s) installed in: $install_dirs"
"$tf" plugins >"$log" 2>&1 || fail "the installed 'trackflow plugins' (default search only) exited non-zero"
searched=$(sed -n 's/^searched: //p' "$log")
for so in $installed; do
  grep -qxF "$prefix/$so" "$log" ||
    fail "installed plugin $prefix/$so is not found by the installed trackflow's default search (searched: $searched)"
done
ok "the installed trackflow finds all of them by default (searched: $searched)"

step "configure and build examples/alpha_beta_plugin against the install"
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S "$example" -B "$plugin_build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$log" 2>&1 || fail "configuring $example with CMAKE_PREFIX_PATH=$prefix failed"
# The package must come from the install, not from a build tree or a system copy.
found=$(sed -n 's/^trackflow_DIR:PATH=//p' "$plugin_build/CMakeCache.txt")
case "$found" in
  "$prefix"/*) ok "find_package(trackflow) used $found" ;;
  *) fail "find_package(trackflow) resolved to '$found', not to the install under $prefix" ;;
esac
cmake --build "$plugin_build" -j 2 >"$log" 2>&1 || fail "building the example plugin against the installed SDK failed"
[ -f "$plugin_build/tfplugin_filter_alpha_beta.so" ] || fail "no tfplugin_filter_alpha_beta.so in $plugin_build"
ok "built $plugin_build/tfplugin_filter_alpha_beta.so"

if [ -x "$plugin_build/test_alpha_beta" ]; then
  step "run the example plugin's own tests"
  ctest --test-dir "$plugin_build" --output-on-failure >"$log" 2>&1 || fail "the example plugin's tests failed"
  ok "$(grep -Eo '[0-9]+% tests passed.*' "$log" | head -n 1)"
  step "every Catch2 test case of the example is one ctest entry"
  printf '%s\t%s\n' "$plugin_build/test_alpha_beta" "alpha_beta:" >"$tmp/catch2_tests.txt"
  bash "$repo/tests/cli/catch_count.sh" ctest "$plugin_build" "$tmp/catch2_tests.txt" >"$log" 2>&1 ||
    fail "the example's Catch2 test cases and its ctest entries differ"
  ok "$(grep -E 'test cases listed' "$log")"
fi

step "trackflow plugins --plugin-path <example build> lists the new type and the installed ones"
"$tf" plugins --plugin-path "$plugin_build" >"$log" 2>&1 || fail "trackflow plugins exited non-zero"
grep -Eq '^  filter\.alpha_beta ' "$log" || fail "filter.alpha_beta is not listed"
ok "filter.alpha_beta listed"
for so in $installed; do
  grep -qxF "$prefix/$so" "$log" || fail "installed plugin $prefix/$so is not listed next to the example"
done
ok "all $in_tree_count installed in-tree plugin(s) listed as well"
grep -q 'convert\.classical' "$log" || fail "convert.classical (needed by the pipeline) is not listed"
ok "convert.classical listed"

pipeline="$example/alpha_beta.yaml"
step "trackflow run alpha_beta.yaml --plugin-path <example build>"
"$tf" run "$pipeline" --plugin-path "$plugin_build" --no-progress --out "$tmp/out" >"$log" 2>&1
rc=$?
[ "$rc" -eq 0 ] || fail "trackflow run exited $rc (expected 0: pipeline runs and its expect: block passes)"
ok "exit 0, expect checks passed"

step "trackflow run fading_memory.yaml: a third-party adapter that rescales P, attached from YAML"
"$tf" run "$example/fading_memory.yaml" --plugin-path "$plugin_build" --no-progress --out "$tmp/out-fm" >"$log" 2>&1
rc=$?
[ "$rc" -eq 0 ] || fail "trackflow run fading_memory.yaml exited $rc (expected 0: its expect: block passes)"
grep -q 'covariance_rescales' "$log" || fail "the adapter's summary (covariance_rescales) is missing"
ok "exit 0: the faded filter's ANEES and RMSE are below the plain filter's"
# Broken on purpose: alpha = 1 rescales by 1, so the expect block must fail (exit 1).
"$tf" run "$example/fading_memory.yaml" --plugin-path "$plugin_build" --no-progress --set fading.alpha=1 \
  --out "$tmp/out-fm1" >"$log" 2>&1
rc=$?
[ "$rc" -eq 1 ] || fail "with fading.alpha=1 (no rescale) trackflow run exited $rc (expected 1: a failed check)"
ok "with alpha = 1 the check fails (exit 1): the pass above comes from the rescale"

step "the same run without --plugin-path fails cleanly"
"$tf" run "$pipeline" --no-progress --out "$tmp/out-missing" >"$log" 2>&1
rc=$?
[ "$rc" -eq 2 ] || fail "trackflow run without the plugin exited $rc (expected 2: bad configuration)"
grep -q "unknown type 'filter.alpha_beta'" "$log" || fail "no \"unknown type 'filter.alpha_beta'\" message"
grep -q 'Available: .*convert\.classical' "$log" || fail "the message does not list the available types"
ok "exit 2 with: $(grep -o "unknown type 'filter.alpha_beta'[^.]*" "$log" | head -n 1) (available types listed)"

echo "PASS: SDK install, third-party plugin build and run"
