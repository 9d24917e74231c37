#!/usr/bin/env bash
# Configures and builds brdf-factor (Release, portable; pass -DBRDF_FACTOR_NATIVE=ON
# for -march=native) into ./build.
# Usage: scripts/build.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" > build-configure.log 2>&1 || {
  cat build-configure.log; exit 1; }
cmake --build build -j "$(nproc)"
