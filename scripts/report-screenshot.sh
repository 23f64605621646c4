#!/usr/bin/env bash
# Opens a run's report.html in a real browser (headless Chromium, installed from Debian if missing)
# and saves a full-page screenshot next to it, to check that the page renders as a person sees it.
# Usage: scripts/report-screenshot.sh [RUN_DIR]   (default: out/replay-mixed-reality)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
run_dir="$(cd "${1:-$root/out/replay-mixed-reality}" && pwd)"
[ -f "$run_dir/report.html" ] || { echo "report-screenshot: no report.html in $run_dir" >&2; exit 1; }
if ! command -v chromium >/dev/null; then
  echo "report-screenshot: installing chromium" >&2
  apt-get install -y -qq chromium >/dev/null
fi
shot="$run_dir/report.png"
# --no-sandbox: CI and this script run as root, where Chromium's sandbox refuses to start.
timeout 120 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1400,3200 \
  --screenshot="$shot.partial.png" "file://$run_dir/report.html" 2>/dev/null
mv "$shot.partial.png" "$shot"
echo "report-screenshot: $shot"
