#!/usr/bin/env bash
# Builds the library, CLI and tests with AddressSanitizer + UndefinedBehaviorSanitizer
# (-DBRDF_FACTOR_SANITIZE=ON: gcc, -O1, every UBSan finding fatal via
# -fno-sanitize-recover=all) into build-asan/ and runs the default test suite
# under them, but for the tests tagged [heavy] (ctest -LE 'slow|heavy': repeats
# of code paths the other tests run; docs/testing.md). Any finding makes a
# test, and so this script, fail.
#   scripts/test-sanitize.sh              every default test but the [heavy] ones
#   scripts/test-sanitize.sh REGEX        only default tests whose name matches
#                                         (ctest -R), [heavy] ones included
# Build dir: $BF_ASAN_BUILD_DIR (default build-asan). Needs only the default
# packages (gcc ships libasan/libubsan): scripts/install-deps.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${BF_ASAN_BUILD_DIR:-build-asan}"
start=$(date +%s)
# -O1 -g1: about half the compile time of -O2 -g, still usable stack traces.
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBRDF_FACTOR_SANITIZE=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  > "$build-configure.log" 2>&1 || { cat "$build-configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)"
built=$(date +%s)
# halt_on_error: the first report ends the process (exit 1), so the test fails.
# detect_leaks: LeakSanitizer is part of ASan on Linux; a leak fails the test too.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# The whole suite: CTest must register exactly the Catch2 test cases.
[ -z "${1:-}" ] && bash scripts/check-test-count.sh "$build"
cd "$build"
args=(--no-tests=error --output-on-failure -j "$(nproc)" --timeout 1800)
if [ -n "${1:-}" ]; then args+=(-LE slow -R "$1"); else args+=(-LE 'slow|heavy'); fi
status=0
ctest "${args[@]}" || status=$?
end=$(date +%s)
echo "test-sanitize: build $((built - start)) s, tests $((end - built)) s (wall, $(nproc) cores)"
exit $status
