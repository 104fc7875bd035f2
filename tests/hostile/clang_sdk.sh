#!/usr/bin/env bash
# Purpose: a plugin author using clang++ can build against the SDK: every SDK header compiles alone with clang++, and examples/alpha_beta_plugin builds with clang++ against an install of this build, passes its tests and runs in the (g++-built) trackflow.
# Usage: clang_sdk.sh <trackflow build dir> <repo root>
set -u
build_dir=${1:?usage: clang_sdk.sh <build dir> <repo root>}
repo=${2:?usage: clang_sdk.sh <build dir> <repo root>}
CXX=$(command -v clang++ || command -v clang++-14 || true)
if [ -z "$CXX" ]; then
  echo "SKIPPED: clang++ is not installed (bash setup.sh test installs it)"
  exit 77
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/trackflow-clang.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
log="$tmp/log"
fail() {
  echo "FAIL: $*" >&2
  [ -s "$log" ] && tail -n 40 "$log" >&2
  exit 1
}
unset TRACKFLOW_PLUGIN_PATH
echo "== $($CXX --version | head -n 1)"

n=0
for h in $(cd "$repo/framework/include" && find trackflow -name '*.hpp' | sort); do
  printf '#include <%s>\n#include <%s>\n' "$h" "$h" > "$tmp/one.cpp"  # twice: include guards too
  "$CXX" -std=c++20 -fsyntax-only -Wall -Wextra -Werror -DBOOST_DLL_USE_STD_FS -I"$repo/framework/include" \
    -isystem /usr/include/eigen3 "$tmp/one.cpp" >"$log" 2>&1 || fail "$h does not compile alone with clang++"
  n=$((n + 1))
done
echo "ok: $n SDK headers compile alone with clang++ -Wall -Wextra -Werror"

prefix="$tmp/prefix"
cmake --install "$build_dir" --prefix "$prefix" >"$log" 2>&1 || fail "cmake --install failed"
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
cmake -S "$repo/examples/alpha_beta_plugin" -B "$tmp/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER="$CXX" -DCMAKE_PREFIX_PATH="$prefix" >"$log" 2>&1 || fail "configuring the example with clang++ failed"
grep -q 'CMAKE_CXX_COMPILER_ID.*Clang\|The CXX compiler identification is Clang' "$log" "$tmp/build/CMakeCache.txt" 2>/dev/null ||
  fail "the example was not configured with clang"
cmake --build "$tmp/build" -j 2 >"$log" 2>&1 || fail "building examples/alpha_beta_plugin with clang++ failed"
echo "ok: examples/alpha_beta_plugin builds with clang++ against the installed SDK"
if [ -x "$tmp/build/test_alpha_beta" ]; then
  # Under `setup.sh sanitize` the installed library is built with GCC's AddressSanitizer while
  # the clang-built test executable is not: the ASan runtime must then come first (LD_PRELOAD),
  # or its exception interceptors miss the throws and leave stale stack poison behind (a false
  # stack-buffer-overflow in the next call into the library).
  if [ -n "${TRACKFLOW_SANITIZE:-}" ]; then
    export LD_PRELOAD="$(g++ -print-file-name=libasan.so)${LD_PRELOAD:+:$LD_PRELOAD}"
  fi
  ctest --test-dir "$tmp/build" >"$log" 2>&1 || fail "the example's tests (clang build) failed"
  unset LD_PRELOAD
  echo "ok: its tests pass"
fi
"$prefix/bin/trackflow" run "$repo/examples/alpha_beta_plugin/alpha_beta.yaml" --plugin-path "$tmp/build" --no-progress \
  --out "$tmp/out" >"$log" 2>&1 || fail "the clang-built plugin does not run in trackflow"
echo "ok: the clang-built plugin runs in trackflow and its expect block passes"
echo "PASS"
