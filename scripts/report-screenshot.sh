#!/usr/bin/env bash
# Regenerates the README's viewer figure (docs/figures/report-viewer.png): runs
# a small experiment (bluepaint on a 12^4 grid, McCool with 16x16 textures) with
# this build's CLI, opens its report.html in Debian's headless Chromium at
# report.html?viewer (the viewer scrolled to the top; a URL with a #fragment
# screenshots blank) and saves the window as a PNG.
#   scripts/report-screenshot.sh [--out FILE] [--size WxH] [--report PATH]
# --out     the PNG to write (default docs/figures/report-viewer.png)
# --size    the window in CSS pixels (default 1100x1365)
# --report  screenshot this report.html instead of running the experiment
# Needs build/experiments/brdf-factor (scripts/build.sh) and chromium
# (scripts/install-deps.sh). Exit 2 with a message naming what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
out=docs/figures/report-viewer.png
size=1100x1365
report=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --size) size="$2"; shift 2 ;;
    --report) report="$2"; shift 2 ;;
    *) echo "report-screenshot: unknown argument '$1' (expected --out FILE, --size WxH, --report PATH)" >&2; exit 2 ;;
  esac
done
if ! [[ "$size" =~ ^[0-9]+x[0-9]+$ ]]; then
  echo "report-screenshot: --size: expected WxH (e.g. 1100x1365), found '$size'" >&2; exit 2
fi
browser=""
for c in chromium chromium-browser; do
  if command -v "$c" > /dev/null 2>&1; then browser="$c"; break; fi
done
[ -n "$browser" ] || { echo "report-screenshot: chromium not found (scripts/install-deps.sh installs it)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ -z "$report" ]; then
  cli=build/experiments/brdf-factor
  [ -x "$cli" ] || { echo "report-screenshot: $cli: not built (run scripts/build.sh)" >&2; exit 2; }
  cat > "$tmp/viewer.toml" <<'TOML'
[experiment]
name = "viewer-figure"
seed = 1
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 12
[[method]]
kind = "mccool"
texture_size = 16
TOML
  "$cli" run "$tmp/viewer.toml" --out "$tmp/out" > "$tmp/run.log" 2>&1 || {
    cat "$tmp/run.log" >&2; echo "report-screenshot: the experiment failed" >&2; exit 2; }
  report="$tmp/out/report.html"
fi
[ -f "$report" ] || { echo "report-screenshot: $report: no such file" >&2; exit 2; }
report=$(cd "$(dirname "$report")" && pwd)/$(basename "$report")
mkdir -p "$(dirname "$out")"
# (--virtual-time-budget made the shot blank here.)
"$browser" --headless --no-sandbox --use-gl=swiftshader --enable-unsafe-swiftshader --disable-gpu-sandbox \
  --hide-scrollbars --window-size="${size/x/,}" \
  --screenshot="$tmp/shot.png" "file://$report?viewer" > "$tmp/chromium.log" 2>&1 || {
  cat "$tmp/chromium.log" >&2; echo "report-screenshot: chromium failed" >&2; exit 2; }
[ -s "$tmp/shot.png" ] || { echo "report-screenshot: chromium wrote no screenshot" >&2; exit 2; }
cp "$tmp/shot.png" "$out"
echo "report-screenshot: wrote $out ($size) from $report"
