#!/bin/sh
# Regenerates run_ids.txt: the --dry-run listing (run ids and descriptions) of
# every run config under experiments/ (stress.toml is the `stress` command's
# input, not a run config). Run from the repository root after a change that
# is MEANT to change run ids:  tests/data/golden/make-run-ids.sh build/experiments/brdf-factor
set -eu
cli=${1:-build/experiments/brdf-factor}
out=tests/data/golden/run_ids.txt
: > "$out"
for f in experiments/*.toml; do
  name=$(basename "$f" .toml)
  [ "$name" = stress ] && continue
  echo "== $name" >> "$out"
  "$cli" run "$f" --dry-run --out /nonexistent/golden >> "$out"
done
