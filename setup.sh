#!/usr/bin/env bash
# Purpose: one-command set-up on Debian bookworm: install missing packages, build what the mode needs, then run the
# quickstart pipeline (`setup.sh run`), the whole test suite (`setup.sh test`) or build the benchmarks (`setup.sh bench`).
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-run}
BUILD=${TRACKFLOW_BUILD_DIR:-build}

# Building and running (MPI: Open MPI through Boost.MPI, for `mpirun -np N trackflow run`).
packages=(g++ cmake ninja-build ccache pkg-config libeigen3-dev libboost-dev libboost-program-options-dev
          libyaml-cpp-dev catch2 nlohmann-json3-dev libboost-mpi-dev openmpi-bin)
case "$mode" in
  run)
    # Only what running needs: the library, the CLI and the plugins.
    options=(-DTRACKFLOW_BUILD_TESTS=OFF -DTRACKFLOW_BUILD_BENCH=OFF)
    ;;
  test)
    # The headless-browser test of the report (tests/report/browser.sh) and a font for its screenshot.
    packages+=(chromium fonts-dejavu-core)
    options=(-DTRACKFLOW_BUILD_TESTS=ON -DTRACKFLOW_BUILD_BENCH=OFF)
    ;;
  bench)
    # The benchmarks (docs/performance.md), with OpenCV's cv::KalmanFilter as the Kalman step's peer.
    packages+=(libopencv-video-dev)
    options=(-DTRACKFLOW_BUILD_TESTS=OFF -DTRACKFLOW_BUILD_BENCH=ON)
    ;;
  *)
    echo "usage: setup.sh [run|test|bench]" >&2
    exit 2
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

echo "== configuring and building in $BUILD/ ($mode)"
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${options[@]}" >/dev/null
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
    echo "== built: $BUILD/bin/trackflow-bench, trackflow-bench-filters, trackflow-bench-gain-transform (docs/performance.md)"
    ;;
esac
