#!/usr/bin/env bash
# Purpose: builds the libFuzzer harnesses with clang++ and runs the three of them side by side for SECONDS each (2 cores: ~0.7 core each), from the seed corpora in the repo; any crash, leak, timeout or sanitizer report fails with the input kept.
# Usage: run_fuzz.sh <repo root> <work dir> [seconds, default 60]
# Exit 77 (ctest: skipped) when clang++ or libFuzzer is not installed.
set -u
repo=${1:?usage: run_fuzz.sh <repo root> <work dir> [seconds]}
work=${2:?usage: run_fuzz.sh <repo root> <work dir> [seconds]}
seconds=${3:-60}
CXX=$(command -v clang++ || command -v clang++-14 || true)
if [ -z "$CXX" ] || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "SKIPPED: clang++ with libFuzzer is not installed (bash setup.sh test installs clang and libfuzzer-14-dev)"
  exit 77
fi
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
mkdir -p "$work"
echo "== building the harnesses with $("$CXX" --version | head -n 1) (ASan+UBSan, libFuzzer)"
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
cmake -S "$repo/tests/fuzz" -B "$work/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER="$CXX" >"$work/build.log" 2>&1 || { tail -n 30 "$work/build.log" >&2; fail "configuring the harnesses failed"; }
cmake --build "$work/build" -j 2 >>"$work/build.log" 2>&1 || { tail -n 30 "$work/build.log" >&2; fail "building the harnesses failed"; }

echo "== running fuzz_config, fuzz_set and fuzz_csv for ${seconds} s each, in parallel"
pids=()
for h in config set csv; do
  rm -rf "$work/$h" && mkdir -p "$work/$h/corpus" "$work/$h/crashes"
  cp "$repo/tests/fuzz/corpus/$h/"* "$work/$h/corpus/"  # the repo's corpus stays as it is
  dict=()
  [ "$h" != csv ] && dict=(-dict="$repo/tests/fuzz/config.dict")
  # -timeout: one input may take at most 10 s (a hang is a failure); -rss_limit_mb: a memory bomb is one.
  "$work/build/fuzz_$h" "$work/$h/corpus" "${dict[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$work/$h/crashes/" >"$work/$h/log" 2>&1 &
  pids+=($!)
done
status=0
i=0
for h in config set csv; do
  wait "${pids[$i]}"
  rc=$?
  i=$((i + 1))
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$h/log")
  cov=$(grep -Eo 'cov: [0-9]+' "$work/$h/log" | tail -n 1)
  if [ "$rc" -ne 0 ] || ls "$work/$h/crashes/"* >/dev/null 2>&1; then
    echo "FAIL: fuzz_$h exited $rc; inputs kept in $work/$h/crashes/:" >&2
    ls "$work/$h/crashes/" >&2
    grep -E 'ERROR|SUMMARY|==[0-9]+==' "$work/$h/log" | head -n 20 >&2
    status=1
  else
    echo "ok: fuzz_$h: ${runs:-?} inputs in ${seconds} s, ${cov:-cov: ?}, 0 crashes"
  fi
done
[ "$status" -eq 0 ] && echo "PASS: 0 crashes"
exit "$status"
