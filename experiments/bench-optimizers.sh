#!/usr/bin/env bash
# Time against error of the search's optimizers and of the number of restarts
# on W1 (bluepaint, wiwo, grid 16, texture 16, 2 textures): one JSON line each.
# Usage: experiments/bench-optimizers.sh [path/to/brdf-factor]
set -euo pipefail
BF=${1:-./build/experiments/brdf-factor}
for opt in powell praxis bobyqa neldermead sbplx direct crs; do
  "$BF" bench search --brdf bluepaint --terms 2 --restarts 2 --optimizer "$opt"
done
for r in 1 4 6; do
  "$BF" bench search --brdf bluepaint --terms 2 --restarts "$r"
done
