#!/usr/bin/env bash
# Checks that CTest runs exactly the Catch2 test cases of the default suite:
# for every test executable BUILD/tests/test_FOLDER, the names Catch lists for
# the spec "~[slow]~[.]" (not slow, not hidden), each prefixed "FOLDER: ", must
# equal the names `ctest -N -LE 'slow|python|docs'` registers, one for one (the
# Python module's pytest suite is one CTest entry labelled python, not a
# Catch test; pytest itself fails on "no tests ran"; the quick-figures check
# of the docs and the include-layer check are entries labelled docs). A TEST_CASE name
# that catch_discover_tests splits (a ';' in it), a hidden test selected, or a
# test executable not registered makes the lists differ and this script fail.
#   scripts/check-test-count.sh [BUILD_DIR]     (default: build)
# Prints "check-test-count: N Catch test cases = N CTest tests" on success.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
[ -d "$build/tests" ] || { echo "check-test-count: $build/tests: no such folder (build first)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

shopt -s nullglob
exes=("$build"/tests/test_*)
found=0
: > "$tmp/catch"
for exe in "${exes[@]}"; do
  [ -f "$exe" ] && [ -x "$exe" ] || continue
  found=1
  folder=$(basename "$exe"); folder=${folder#test_}
  # --list-test-names-only exits with the number of tests listed: not an error.
  "$exe" '~[slow]~[.]' --list-test-names-only > "$tmp/list" || true
  sed -e '/^$/d' -e "s/^/$folder: /" "$tmp/list" >> "$tmp/catch"
done
[ "$found" = 1 ] || { echo "check-test-count: no test executable in $build/tests" >&2; exit 1; }

# CTest shows the prefix "FOLDER: " as "FOLDER:" (the discovery drops its
# trailing space): normalize it before comparing.
(cd "$build" && ctest -N -LE 'slow|python|docs') | sed -n 's/^ *Test *#[0-9]*: //p' |
  sed 's/^\([^:]*\): */\1: /' > "$tmp/ctest"
sort "$tmp/catch" > "$tmp/catch.sorted"
sort "$tmp/ctest" > "$tmp/ctest.sorted"
n_catch=$(wc -l < "$tmp/catch.sorted")
n_ctest=$(wc -l < "$tmp/ctest.sorted")
if ! cmp -s "$tmp/catch.sorted" "$tmp/ctest.sorted"; then
  echo "check-test-count: FAILED: $n_catch Catch test cases (not [slow], not hidden), $n_ctest CTest tests (ctest -N -LE 'slow|python|docs')" >&2
  echo "  '<' only in Catch's list (never run by CTest), '>' only in CTest's (matches no Catch test):" >&2
  diff "$tmp/catch.sorted" "$tmp/ctest.sorted" | grep '^[<>]' | head -40 | sed 's/^/  /' >&2 || true
  echo "  A TEST_CASE name must not contain ';' (catch_discover_tests splits it there) or '[' / ']' (it merges later tests into one entry)." >&2
  exit 1
fi
if [ "$n_catch" -eq 0 ]; then
  echo "check-test-count: FAILED: no test case found" >&2
  exit 1
fi
echo "check-test-count: $n_catch Catch test cases = $n_ctest CTest tests (default suite, $build)"
