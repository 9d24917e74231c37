#!/usr/bin/env bash
# Time against error of the search's optimizers, of the number of restarts and
# of the non-greedy options on W1 (bluepaint, wiwo, grid 16, texture 16, 2
# textures): one JSON line each (bench search) into OUT.jsonl, then the table
# and plot of experiments/report/plot_time_error.py (OUT.png, x = process CPU seconds).
# Usage: experiments/bench-optimizers.sh [path/to/brdf-factor] [OUT.jsonl] [all|optimizers|restarts|nongreedy]
set -euo pipefail
BF=${1:-./build/experiments/brdf-factor}
OUT=${2:-bench-optimizers.jsonl}
WHAT=${3:-all}
: > "$OUT"
b() { echo "# $*" >> "$OUT"; "$BF" bench search --brdf bluepaint --terms 2 "$@" | tee -a "$OUT"; }
if [[ $WHAT == all || $WHAT == optimizers ]]; then
  for opt in powell praxis bobyqa neldermead sbplx direct crs; do b --restarts 2 --optimizer "$opt"; done
fi
if [[ $WHAT == all || $WHAT == restarts ]]; then
  for r in 1 2 4 6; do
    # powell with 2 restarts is already a row of the optimizer sweep.
    [[ $WHAT == all && $r == 2 ]] && continue
    b --restarts "$r"
  done
fi
if [[ $WHAT == all || $WHAT == nongreedy ]]; then
  b --restarts 6 --backfit-sweeps 2
  b --restarts 6 --beam 3
  b --restarts 6 --beam 6
fi
/usr/bin/python3 "$(dirname "$0")/plot_time_error.py" "$OUT" "${OUT%.jsonl}.png" --cpu
