#!/usr/bin/env bash
# Purpose: one-command set-up on Debian bookworm: install missing packages, build what the mode needs, then
# run the quickstart pipeline (`setup.sh run`), the whole test suite (`setup.sh test`), build the
# benchmarks (`setup.sh bench`), or run the suite built with AddressSanitizer and
# UndefinedBehaviorSanitizer (`setup.sh sanitize`).
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-run}
case "$mode" in
  run | test | bench) BUILD=${TRACKFLOW_BUILD_DIR:-build} ;;
  sanitize) BUILD=${TRACKFLOW_BUILD_DIR:-build-sanitize} ;;
  *)
    echo "usage: setup.sh [run|test|bench|sanitize]" >&2
    exit 2
    ;;
esac

# Building and running (MPI: Open MPI through Boost.MPI, for `mpirun -np N trackflow run`; {fmt},
# header-only, for sink.csv's shortest numbers).
packages=(g++ cmake ninja-build ccache pkg-config libeigen3-dev libboost-dev libboost-program-options-dev
          libyaml-cpp-dev catch2 nlohmann-json3-dev libgeographiclib-dev libboost-mpi-dev openmpi-bin libfmt-dev)
case "$mode" in
  run)
    # Only what running needs: the library, the CLI and the plugins.
    options=(-DTRACKFLOW_BUILD_TESTS=OFF -DTRACKFLOW_BUILD_BENCH=OFF)
    ;;
  test | sanitize)
    # The headless-browser test of the report (tests/report/browser.sh) and a font for its
    # screenshot; clang++ and libFuzzer for the fuzz harnesses (tests/fuzz) and the clang build of
    # the SDK; SciPy for the check that the assignment solver's committed SciPy answers are still
    # SciPy's (plugins/lib/assignment/make_scipy_cases.py --check); PyYAML for the check that every
    # YAML snippet in the docs validates (tests/support/docs_snippets.py). Benchmarks are not built
    # for tests (and mean nothing under ASan).
    packages+=(chromium fonts-dejavu-core clang libfuzzer-14-dev python3-scipy python3-yaml)
    options=(-DTRACKFLOW_BUILD_TESTS=ON -DTRACKFLOW_BUILD_BENCH=OFF)
    ;;
  bench)
    # The benchmarks (docs/performance.md), with OpenCV's cv::KalmanFilter as the Kalman step's peer
    # ({fmt}, std::to_chars' peer in trackflow-bench-number-format, is in every mode's list); GNU
    # time and python3 for the memory scripts (bench/memory_hostile.sh, bench/memory_long_log.sh).
    packages+=(libopencv-video-dev time python3)
    options=(-DTRACKFLOW_BUILD_TESTS=OFF -DTRACKFLOW_BUILD_BENCH=ON)
    ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Compiler-cache entries relative to the tree, so that another copy of it (the plugin guide's
# own SDK build in tests/cli/plugin_guide.sh) finds them.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd -P)}"
echo "== configuring and building in $BUILD/ ($mode)"
if [ "$mode" = sanitize ]; then
  # -fno-gnu-unique: plugins' inline statics stay local to each .so (unique symbols would bind
  # them across libraries). Benchmarks are not built: their timings mean nothing under ASan.
  san="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -fno-gnu-unique"
  # -O1 -g1: half the compile time of -O2 -g, and reports still carry file:line.
  cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${options[@]}" -DTRACKFLOW_TEST_TIMEOUT_SCALE=4 \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DCMAKE_CXX_FLAGS="$san" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
else
  cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${options[@]}" >/dev/null
fi
cmake --build "$BUILD" -j2

case "$mode" in
  run)
    echo "== trackflow run pipelines/quickstart.yaml --threads 2"
    "$BUILD/bin/trackflow" run pipelines/quickstart.yaml --threads 2
    ;;
  test)
    echo "== ctest"
    ctest --test-dir "$BUILD" -j2 --output-on-failure --timeout 900
    ;;
  bench)
    echo "== built: $BUILD/bin/trackflow-bench, trackflow-bench-filters, trackflow-bench-gain-transform, trackflow-bench-csv (docs/performance.md)"
    ;;
  sanitize)
    # A report stops the process with exit code 86, which no test expects. ASan and LSan reports
    # also go to files under $BUILD/sanitizer-reports (found even where a test ignores an exit
    # code); UBSan's go to stderr (GCC's runtime ignores its log_path next to ASan), so the ctest
    # log is searched for them too.
    reports="$(pwd)/$BUILD/sanitizer-reports"
    rm -rf "$reports" && mkdir -p "$reports"
    export ASAN_OPTIONS="log_path=$reports/asan:exitcode=86:detect_leaks=1:verify_asan_link_order=0:detect_stack_use_after_return=0"
    export UBSAN_OPTIONS="log_path=$reports/ubsan:exitcode=86:halt_on_error=1:print_stacktrace=1"
    export LSAN_OPTIONS="suppressions=$(pwd)/tests/sanitize/lsan.supp"
    export TRACKFLOW_SANITIZE=1  # scripts that cannot run under ASan (address-space limits) skip, saying so
    echo "== ctest (ASan + UBSan)"
    start=$(date +%s)
    rc=0
    ctest --test-dir "$BUILD" -j2 --output-on-failure --timeout 1800 || rc=$?
    echo "== ctest took $(( $(date +%s) - start )) s"
    if ls "$reports"/* >/dev/null 2>&1; then
      echo "== sanitizer reports:"
      for f in "$reports"/*; do echo "---- $f"; head -n 40 "$f"; done
      exit 1
    fi
    if grep -E "runtime error:|ERROR: (AddressSanitizer|LeakSanitizer)" "$BUILD/Testing/Temporary/LastTest.log"; then
      echo "== sanitizer reports in the test output (above)"
      exit 1
    fi
    echo "== 0 sanitizer reports"
    exit "$rc"
    ;;
esac
