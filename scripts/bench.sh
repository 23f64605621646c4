#!/usr/bin/env bash
# Installs what is missing (plus the benchmark-only packages of scripts/debian-packages-bench.txt:
# PCL for the normal-estimation baselines), builds Release and runs relight-bench. Every result is
# printed as a JSON line and collected in out/bench/bench.json and out/bench/bench.md (a Markdown
# table with the end-to-end pipeline/replay_640x480 breakdown); RELIGHT_BENCH_OUT moves them.
# Usage: scripts/bench.sh [FILTER]   (e.g. scripts/bench.sh dir/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
lists=("$root/scripts/debian-packages.txt")
[ -f "$root/scripts/debian-packages-bench.txt" ] && lists+=("$root/scripts/debian-packages-bench.txt")
"$root/scripts/install-deps.sh" "${lists[@]}"
source "$root/scripts/common.sh"
relight_build default
out="${RELIGHT_BENCH_OUT:-$root/out/bench}"
"$root/build/release/bench/relight-bench" --report "$out" "$@"
echo "bench.sh: results in $out/bench.md and $out/bench.json" >&2
