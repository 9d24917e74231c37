#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, build dir build-fuzz/) and
# runs each for a fixed time, in parallel.
#   fuzz/run.sh [SECONDS [TARGET...]]     default: 600 s, every target
# Targets: merl astm pbrt_brdf csv sidecar config. Seeds come from
# fuzz/corpus/<target>/; the growing working corpus lives in
# build-fuzz/corpus/<target>/; crashing, leaking or slow inputs are saved as
# fuzz/corpus/<target>/{crash,leak,timeout,oom}-<sha1>; logs in build-fuzz/logs/.
# Exit code: 0 if no target found anything, 1 otherwise.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
build="${BF_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${1:-600}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(merl astm pbrt_brdf csv sidecar config)

extra=()
# Until the top-level CMakeLists.txt adds fuzz/ under BRDF_FACTOR_FUZZ, hook it in.
grep -q 'add_subdirectory(fuzz)' "$root/CMakeLists.txt" ||
  extra+=("-DCMAKE_PROJECT_brdf_factor_INCLUDE=$here/hook.cmake")
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBRDF_FACTOR_FUZZ=ON -DBRDF_FACTOR_BUILD_TESTS=OFF -DBRDF_FACTOR_NATIVE=OFF "${extra[@]}" >/dev/null
ninja -C "$build" "${targets[@]/#/fuzz_}"

mkdir -p "$build/logs"
pids=()
for t in "${targets[@]}"; do
  mkdir -p "$build/corpus/$t" "$here/corpus/$t"
  # -rss_limit_mb: a reader must not allocate without bound (DESIGN.md §7).
  "$build/fuzz/fuzz_$t" "$build/corpus/$t" "$here/corpus/$t" -max_total_time="$seconds" \
    -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$here/corpus/$t/" >"$build/logs/$t.log" 2>&1 &
  pids+=($!)
done
status=0
for i in "${!pids[@]}"; do
  if wait "${pids[$i]}"; then
    echo "fuzz_${targets[$i]}: ran ${seconds}s, nothing found"
  else
    echo "fuzz_${targets[$i]}: FOUND something, see $build/logs/${targets[$i]}.log"
    status=1
  fi
done
exit $status
