#!/usr/bin/env bash
# Keeps what a fuzz run learned: merges the working corpus build-fuzz/corpus/<t>/
# into the committed seed corpus fuzz/corpus/<t>/, adding only inputs that add
# coverage (libFuzzer -merge=1), so the committed corpus stays small.
#   fuzz/merge.sh [TARGET...]     default: every target; run after fuzz/run.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
build="${BF_FUZZ_BUILD_DIR:-$root/build-fuzz}"
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(merl astm pbrt_brdf csv sidecar config merge)
for t in "${targets[@]}"; do
  [ -x "$build/fuzz/fuzz_$t" ] || { echo "fuzz/merge.sh: $build/fuzz/fuzz_$t not built (fuzz/run.sh builds it)" >&2; exit 2; }
  mkdir -p "$here/corpus/$t" "$build/corpus/$t"
  before=$(ls "$here/corpus/$t" | wc -l)
  max_len=65536
  case "$t" in config|merge) max_len=262144 ;; esac
  "$build/fuzz/fuzz_$t" -merge=1 -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" \
    "$here/corpus/$t" "$build/corpus/$t" >"$build/logs/merge-$t.log" 2>&1
  echo "fuzz_$t: fuzz/corpus/$t $before -> $(ls "$here/corpus/$t" | wc -l) files ($(grep -o 'MERGE-OUTER: [0-9]* new files with [0-9]* new features' "$build/logs/merge-$t.log" | tail -1))"
done
