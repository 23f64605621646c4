#!/usr/bin/env bash
# Installs what is missing, builds the Release binaries and runs the main job on the embedded
# sample: `relight replay` with no arguments - the shipped glossy pebble stood on the desk of the
# real TUM slice (its support plane, found in the first frame), lit by 8 lights of the light
# estimated from the slice's own frames (the TUM recording has no light probe),
# results in out/replay (or RELIGHT_OUT): frames/*_composite.png before and *_composite_mapped.png
# after colour mapping, composite.mp4, report.html. Then the same on a short synthetic sequence
# (`relight synth`, with its own light probe and exact geometry), results in
# out/replay-mixed-reality, and on that sequence the glass pebble beside the aluminium bottle
# (reflections, refractions and caustics), results in out/replay-glass; and the glass pebble on
# the real TUM desk, results in out/replay-glass-tum.
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
glass="$out-glass"
"$relight" replay "$mixed/sequence" --object "$root/data/models/glass_pebble.gltf" --place 0.35,-0.2,0.75,30 \
  --object "$root/data/models/metal_bottle.gltf" --place 0.1,-0.3,0.75 --out "$glass"
glass_tum="$out-glass-tum"
"$relight" replay --object "$root/data/models/glass_pebble.gltf" --place-on-plane \
  --lights estimate --composite multiplicative --out "$glass_tum"
echo "Results (open report.html in each): $out, $mixed, $glass, $glass_tum"
