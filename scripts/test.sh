#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default test suite (every
# test not tagged [slow]). `scripts/test.sh slow` runs only the slow ones.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
cd build
if [ "${1:-}" = "slow" ]; then
  ctest -L slow --output-on-failure -j "$(nproc)"
else
  ctest -LE slow --output-on-failure -j "$(nproc)" --timeout 600
fi
