#!/usr/bin/env bash
# Purpose: one-command set-up on Debian bookworm: install missing packages, build, then run the
# quickstart pipeline (`setup.sh run`) or the whole test suite (`setup.sh test`).
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-run}
BUILD=${TRACKFLOW_BUILD_DIR:-build}

packages=(g++ cmake ninja-build ccache pkg-config libeigen3-dev libboost-dev libboost-program-options-dev
          libyaml-cpp-dev catch2 nlohmann-json3-dev libgeographiclib-dev)
# Test only: the headless-browser test of the report (tests/report/browser.sh) and a font for its screenshot.
if [ "$mode" = test ]; then packages+=(chromium fonts-dejavu-core); fi
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

echo "== configuring and building in $BUILD/"
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
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
  *)
    echo "usage: setup.sh [run|test]" >&2
    exit 2
    ;;
esac
