#!/usr/bin/env bash
# Installs what is missing, builds the Release binaries and runs the main job on the embedded
# sample: `relight replay` with no arguments. Results go to out/replay (or RELIGHT_OUT).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
source "$root/scripts/common.sh"
relight_build default
out="${RELIGHT_OUT:-$root/out/replay}"
"$root/build/release/app/relight" replay --out "$out" "$@"
echo "Results: $out (open $out/report.json)"
