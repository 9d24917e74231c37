#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default test suite (every
# test not tagged [slow]). `scripts/test.sh slow` runs only the slow ones.
# Before running, scripts/check-test-count.sh checks that CTest registers exactly
# the Catch2 test cases; --no-tests=error fails a run that selects none
# (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
cd build
if [ "${1:-}" = "slow" ]; then
  ctest -L slow --no-tests=error --output-on-failure -j "$(nproc)"
else
  bash ../scripts/check-test-count.sh build
  ctest -LE slow --no-tests=error --output-on-failure -j "$(nproc)" --timeout 600
fi
