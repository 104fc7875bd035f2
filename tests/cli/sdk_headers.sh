#!/usr/bin/env bash
# Purpose: the installed SDK is free of the host: no host header is installed, the installed headers compile (g++ and clang++) with only the install's include folder, and no in-tree plugin needs the host library.
# Usage: sdk_headers.sh <trackflow build dir>
set -u
build_dir=${1:?usage: sdk_headers.sh <trackflow build dir>}
source "$(dirname "$0")/lib.sh"  # TMP (removed on exit), fail
tmp=$TMP
log="$tmp/log"
# A failure shows the end of the failing step's output first.
fail_step() {
  [ -s "$log" ] && tail -n 30 "$log" >&2
  fail "$@"
}
prefix="$tmp/prefix"
cmake --install "$build_dir" --prefix "$prefix" >"$log" 2>&1 || fail_step "cmake --install $build_dir failed"
inc="$prefix/include"
[ -f "$inc/trackflow/component.hpp" ] || fail_step "the install has no trackflow/component.hpp under $inc"
[ ! -e "$inc/trackflow/host" ] || fail_step "the install contains the host's headers ($inc/trackflow/host)"
if grep -rn "trackflow/host/" "$inc/trackflow" >"$log"; then
  fail_step "installed SDK headers include host headers (above)"
fi
echo "ok: no host header installed or included"

compilers=(g++)
CLANG=$(command -v clang++ || command -v clang++-14 || true)
[ -n "$CLANG" ] && compilers+=("$CLANG")
# One translation unit of all installed headers per compiler: a header reaching for anything not
# installed (the host's) fails here. That each header also compiles on its own is checked by
# tests/hostile/clang_sdk.sh.
headers=$(cd "$inc" && find trackflow -name '*.hpp' | sort)
n=$(echo "$headers" | wc -l)
[ "$n" -ge 10 ] || fail_step "only $n installed headers found"
for h in $headers; do printf '#include <%s>\n' "$h"; done > "$tmp/all.cpp"
for cxx in "${compilers[@]}"; do
  "$cxx" -std=c++20 -fsyntax-only -Wall -Wextra -Werror -DBOOST_DLL_USE_STD_FS -I"$inc" \
    -isystem /usr/include/eigen3 "$tmp/all.cpp" >"$log" 2>&1 || fail_step "the installed SDK headers do not compile with $cxx and only the install's include folder"
  echo "ok: $n installed SDK headers compile with $($cxx --version | head -n 1), nothing but the install included"
done
[ -n "$CLANG" ] || echo "note: clang++ not installed; checked with g++ only (bash setup.sh test installs clang)"

# Every in-tree plugin links the SDK library alone (they are linked with --no-undefined, so a host
# symbol would not link; this checks what the loader will map).
plugins=$(find "$build_dir/lib/trackflow/plugins" -name 'tfplugin_*.so' | sort)
[ -n "$plugins" ] || fail_step "no plugins under $build_dir/lib/trackflow/plugins"
count=0
for so in $plugins; do
  needed=$(readelf -d "$so" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p')
  echo "$needed" | grep -qx 'libtrackflow_sdk.so.0' || fail_step "$so does not link libtrackflow_sdk.so.0 (needs: $needed)"
  if echo "$needed" | grep -q '^libtrackflow\.so'; then fail_step "$so needs the host library libtrackflow.so"; fi
  count=$((count + 1))
done
echo "ok: $count in-tree plugins need libtrackflow_sdk.so.0 and not the host library"
