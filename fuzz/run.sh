#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, build dir build-fuzz/) and
# runs each for a fixed time, one after the other (BF_FUZZ_PARALLEL=1: all at
# once, one core each).
#   fuzz/run.sh [SECONDS [TARGET...]]     default: 600 s, every target
# Needs clang and libFuzzer/sanitizer runtimes: scripts/install-deps.sh --fuzz.
# Targets: merl astm pbrt_brdf csv sidecar config merge. Inputs up to 64 KiB,
# 256 KiB for config and merge (a config nested 35,000 deep is 70 KB). Seeds come from
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
[ ${#targets[@]} -eq 0 ] && targets=(merl astm pbrt_brdf csv sidecar config merge)

command -v clang++ >/dev/null || { echo "fuzz/run.sh: clang++ not found; run scripts/install-deps.sh --fuzz" >&2; exit 2; }
# -U...INCLUDE: build dirs configured before fuzz/ was part of the top-level
# CMakeLists.txt still carry the old hook.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBRDF_FACTOR_FUZZ=ON -DBRDF_FACTOR_BUILD_TESTS=OFF -DBRDF_FACTOR_NATIVE=OFF \
  -UCMAKE_PROJECT_brdf_factor_INCLUDE >/dev/null
ninja -C "$build" "${targets[@]/#/fuzz_}"

mkdir -p "$build/logs"
max_len_of() {  # the largest input per target
  case "$1" in config|merge) echo 262144 ;; *) echo 65536 ;; esac
}
run_one() {  # run_one TARGET: fuzz it for $seconds, report, return libFuzzer's status
  local t="$1"
  mkdir -p "$build/corpus/$t" "$here/corpus/$t"
  # -rss_limit_mb: a reader must not allocate without bound (docs/design.md §7).
  if "$build/fuzz/fuzz_$t" "$build/corpus/$t" "$here/corpus/$t" -max_total_time="$seconds" \
      -timeout=10 -rss_limit_mb=2048 -max_len="$(max_len_of "$t")" -print_final_stats=1 \
      -artifact_prefix="$here/corpus/$t/" >"$build/logs/$t.log" 2>&1; then
    echo "fuzz_$t: ran ${seconds}s, nothing found ($(grep -o 'cov: [0-9]* ft: [0-9]*' "$build/logs/$t.log" | tail -1))"
  else
    echo "fuzz_$t: FOUND something, see $build/logs/$t.log"
    return 1
  fi
}
status=0
if [ "${BF_FUZZ_PARALLEL:-0}" = 1 ]; then
  pids=()
  for t in "${targets[@]}"; do run_one "$t" & pids+=($!); done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
else
  for t in "${targets[@]}"; do run_one "$t" || status=1; done
fi
exit $status
