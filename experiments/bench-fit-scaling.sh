#!/usr/bin/env bash
# Scaling of the inner-loop fit (bench fit) with samples and texture size on
# bluepaint, wiwo, 2 terms joint: one JSON line per configuration.
# Usage: experiments/bench-fit-scaling.sh [path/to/brdf-factor]
set -euo pipefail
BF=${1:-./build/experiments/brdf-factor}
for n in 10000 100000 300000 1000000; do
  "$BF" bench fit --brdf bluepaint --samples "$n" --texture 16 --repeats 7
done
"$BF" bench fit --brdf bluepaint --grid 16 --texture 16 --repeats 15
for t in 8 24 32 64; do
  reps=7; [ "$t" -ge 64 ] && reps=3
  "$BF" bench fit --brdf bluepaint --grid 16 --texture "$t" --repeats "$reps"
done
"$BF" bench fit --brdf bluepaint --grid 16 --texture 16 --repeats 15 --reciprocity
"$BF" bench fit --brdf bluepaint --grid 16 --texture 16 --repeats 15 --parameterization halfdiff
