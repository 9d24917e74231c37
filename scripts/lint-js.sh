#!/usr/bin/env bash
# Lints the JavaScript of report.html's viewer (experiments/report/viewer/*.js,
# embedded in the page at build time) with ESLint, rules in
# scripts/eslint/eslint.config.mjs. ESLint is the pinned npm package in
# scripts/eslint/ (package-lock.json), installed there by scripts/install-deps.sh;
# once installed this runs offline. Exit 0 clean, 1 on a lint error, 2 when
# ESLint is not installed.
#   scripts/lint-js.sh [FILE.js ...]     (default: every experiments/report/viewer/*.js)
set -euo pipefail
cd "$(dirname "$0")/.."
eslint=scripts/eslint/node_modules/.bin/eslint
if [ ! -x "$eslint" ]; then
  echo "lint-js: $eslint: not installed (run scripts/install-deps.sh, which runs npm ci in scripts/eslint/)" >&2
  exit 2
fi
if [ $# -eq 0 ]; then set -- experiments/report/viewer/*.js; fi
exec "$eslint" --no-warn-ignored --max-warnings 0 --config scripts/eslint/eslint.config.mjs "$@"
