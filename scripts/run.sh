#!/usr/bin/env bash
# Installs what is missing, builds the Release binaries and runs the main job on the embedded
# sample: `relight replay` with no arguments (results in out/replay, or RELIGHT_OUT), then the
# mixed-reality part: a short synthetic sequence (`relight synth`, with its own light probe) with
# the shipped pebble rendered into every frame (results in out/replay-mixed-reality).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
source "$root/scripts/common.sh"
relight_build default
out="${RELIGHT_OUT:-$root/out/replay}"
relight="$root/build/release/app/relight"
"$relight" replay --out "$out" "$@"
mixed="$out-mixed-reality"
"$relight" synth --quiet --frames 8 --out "$mixed/sequence"
"$relight" replay "$mixed/sequence" --object "$root/data/models/glossy_pebble.gltf" --out "$mixed"
echo "Results: $out (open $out/report.json) and $mixed (frames/*_composite.png, composite.mp4)"
