#!/usr/bin/env bash
# Soak run: replays the embedded sample in a loop for 1 000 and then 10 000 frames and compares the
# peak resident memory of the two runs (report.json's peak_rss_mb): memory must stay flat, i.e. the
# long run may not need more than the short one plus a small margin. Not part of CI (it takes
# several minutes), geometry only (--no-object); extra arguments go to both replays (e.g.
# --object ... --place-on-plane to soak the renderer).
# Usage: scripts/soak.sh [replay options]     RELIGHT_SOAK_FRAMES=10000 sets the long run's length
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
source "$root/scripts/common.sh"
relight_build default
relight="$root/build/release/app/relight"
out="${RELIGHT_OUT:-$root/out/soak}"
long="${RELIGHT_SOAK_FRAMES:-10000}"
frames_per_loop=$("$relight" replay --quiet --no-frames --no-video --no-object --out "$out/probe" "$@" >/dev/null &&
  sed -n 's/^  "frames": \([0-9]*\),*$/\1/p' "$out/probe/report.json")
peak() { sed -n 's/^  "peak_rss_mb": \([0-9.]*\),*$/\1/p' "$1/report.json"; }
for frames in 1000 "$long"; do
  loops=$(( (frames + frames_per_loop - 1) / frames_per_loop ))
  echo "soak: $frames frames ($loops loops of $frames_per_loop)" >&2
  "$relight" replay --quiet --no-frames --no-video --no-object --loop "$loops" \
    --out "$out/run-$frames" "$@"
done
short_mb=$(peak "$out/run-1000")
long_mb=$(peak "$out/run-$long")
echo "soak: peak RSS ${short_mb} MB after 1000 frames, ${long_mb} MB after $long frames"
# Flat: at most 5 % (and 16 MB) above the short run.
awk -v s="$short_mb" -v l="$long_mb" 'BEGIN { exit !(l <= s * 1.05 + 16) }' ||
  { echo "soak: memory grew from ${short_mb} MB to ${long_mb} MB" >&2; exit 1; }
