#!/usr/bin/env bash
# Installs what is missing, builds, and runs the quickstart experiment
# (experiments/quickstart.toml), then prints where its results are.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
./build/experiments/brdf-factor run experiments/quickstart.toml --out results/quickstart
echo
echo "quickstart results: $(pwd)/results/quickstart/results.md"
echo "report:             $(pwd)/results/quickstart/report.html"
