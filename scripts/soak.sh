#!/usr/bin/env bash
# Soak runs, not part of CI (they take from minutes to an hour); each compares a run of 1 000
# frames with one of RELIGHT_SOAK_FRAMES (default 10 000) and fails when the long one grew:
#   scripts/soak.sh [replay options]       replays the embedded sample in a loop, geometry only
#                                          (--no-object); extra arguments go to both replays (e.g.
#                                          --object ... --place-on-plane to soak the renderer)
#   scripts/soak.sh live [live options]    relight live on the synthetic OpenNI2 device (320x240,
#                                          a 60-frame loop) with the pebble rendered
# Checked from each run's report.json: peak resident memory (the long run at most 5 % and 16 MB
# above the short one), open file descriptors at the end (equal) and, for the live soak, Vulkan
# device memory allocations after frame 2 (none in either run). The live soak tracks the camera,
# and the tracker's keyframe model grows by design until its budget (RgbdOdometryOptions::
# model_budget_mb; on the looping orbit about a keyframe a loop): there the memory compared is
# the peak less the model's size at the end (report.json's tracking.keyframe_model_mb), and the
# model itself must stay within the budget the report states (tracking.keyframe_model_budget_mb).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
source "$root/scripts/common.sh"
# RELIGHT_BIN: an existing relight executable instead of building the Release one.
relight="${RELIGHT_BIN:-}"
if [ -z "$relight" ]; then
  relight_build default
  relight="$root/build/release/app/relight"
fi
out="${RELIGHT_OUT:-$root/out/soak}"
long="${RELIGHT_SOAK_FRAMES:-10000}"
mode=replay
if [ "${1:-}" = live ]; then
  mode=live
  shift
fi
field() { sed -n "s/^  \"$2\": \([0-9.]*\),*\$/\1/p" "$1/report.json"; }
tracking_field() { sed -n "s/^    \"$2\": \([0-9.]*\),*\$/\1/p" "$1/report.json" | head -1; }
after_frame_2() { sed -n 's/^    "allocations_after_frame_2": \([0-9]*\)$/\1/p' "$1/report.json"; }

if [ "$mode" = live ]; then
  device='relight://synthetic?size=320x240&loop=60'
  for frames in 1000 "$long"; do
    echo "soak: relight live, $frames frames" >&2
    "$relight" live --quiet --no-frames --device "$device" --frames "$frames" \
      --object "$root/data/models/glossy_pebble.gltf" --out "$out/live-$frames" "$@"
  done
  runs=("$out/live-1000" "$out/live-$long")
else
  frames_per_loop=$("$relight" replay --quiet --no-frames --no-video --no-object --out "$out/probe" "$@" >/dev/null &&
    field "$out/probe" frames)
  for frames in 1000 "$long"; do
    loops=$(( (frames + frames_per_loop - 1) / frames_per_loop ))
    echo "soak: $frames frames ($loops loops of $frames_per_loop)" >&2
    "$relight" replay --quiet --no-frames --no-video --no-object --loop "$loops" \
      --out "$out/run-$frames" "$@"
  done
  runs=("$out/run-1000" "$out/run-$long")
fi

short_mb=$(field "${runs[0]}" peak_rss_mb)
long_mb=$(field "${runs[1]}" peak_rss_mb)
short_fds=$(field "${runs[0]}" open_file_descriptors)
long_fds=$(field "${runs[1]}" open_file_descriptors)
short_model=0
long_model=0
if [ "$mode" = live ]; then
  short_model=$(tracking_field "${runs[0]}" keyframe_model_mb)
  long_model=$(tracking_field "${runs[1]}" keyframe_model_mb)
  short_model=${short_model:-0}
  long_model=${long_model:-0}
fi
short_frames=$(field "${runs[0]}" frames)
long_frames=$(field "${runs[1]}" frames)
echo "soak ($mode): peak RSS ${short_mb} MB after ${short_frames} frames, ${long_mb} MB after ${long_frames} frames" \
  "(keyframe model ${short_model} and ${long_model} MB); open file descriptors ${short_fds} and ${long_fds}"
status=0
# Flat: at most 5 % (and 16 MB) above the short run, the keyframe model aside.
awk -v s="$short_mb" -v l="$long_mb" -v sm="$short_model" -v lm="$long_model" \
  'BEGIN { exit !(l - lm <= (s - sm) * 1.05 + 16) }' ||
  { echo "soak: memory grew from ${short_mb} MB to ${long_mb} MB (keyframe model ${short_model} -> ${long_model} MB)" >&2; status=1; }
if [ "$mode" = live ]; then
  budget_mb=$(tracking_field "${runs[1]}" keyframe_model_budget_mb)
  if [ -z "$budget_mb" ]; then
    echo "soak: ${runs[1]}/report.json states no tracking.keyframe_model_budget_mb" >&2
    status=1
  elif ! awk -v lm="$long_model" -v b="$budget_mb" 'BEGIN { exit !(lm <= b) }'; then
    echo "soak: the keyframe model holds ${long_model} MB, over its ${budget_mb} MB budget" >&2
    status=1
  fi
fi
[ "$short_fds" = "$long_fds" ] ||
  { echo "soak: open file descriptors grew from ${short_fds} to ${long_fds}" >&2; status=1; }
if [ "$mode" = live ]; then
  for run in "${runs[@]}"; do
    allocations=$(after_frame_2 "$run")
    echo "soak (live): $(basename "$run"): ${allocations:-no} Vulkan memory allocations after frame 2"
    [ "${allocations:-0}" = 0 ] || { echo "soak: $run allocated Vulkan memory after frame 2" >&2; status=1; }
  done
fi
exit "$status"
