#!/usr/bin/env bash
# Installs what is missing, builds the Release binaries and runs the main job on the embedded
# sample: `relight replay` with no arguments (results in out/replay, or RELIGHT_OUT), then the
# mixed-reality part: a short synthetic sequence (`relight synth`, with its own light probe) with
# the shipped pebble rendered into every frame (results in out/replay-mixed-reality), and the
# pebble on the desk of the real TUM slice, lit by 8 lights extracted from the shipped Grace
# Cathedral probe (a stand-in: the TUM recording has no probe of its own), results in
# out/replay-tum-pebble (frames/*_composite.png before and *_composite_mapped.png after colour
# mapping). Each results folder has a report.html.
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
tum="$out-tum-pebble"
mkdir -p "$tum"
"$relight" lights "$root/data/probes/grace_latlong.hdr" --n 8 --quiet --out "$tum/lights.json"
# World frame of the TUM ground truth (z up): the desk top is at z = 0.86 m in front of the camera.
"$relight" replay "$root/data/tum_fr1_rpy" --object "$root/data/models/glossy_pebble.gltf" \
  --place 0.95,1.40,0.86,0 --lights "$tum/lights.json" --out "$tum"
echo "Results (open report.html in each): $out, $mixed, $tum"
