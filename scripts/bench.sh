#!/usr/bin/env bash
# Installs what is missing (plus benchmark-only packages from scripts/debian-packages-bench.txt,
# when that list exists), builds Release and runs relight-bench.
# Usage: scripts/bench.sh [FILTER]   (e.g. scripts/bench.sh synth/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
lists=("$root/scripts/debian-packages.txt")
[ -f "$root/scripts/debian-packages-bench.txt" ] && lists+=("$root/scripts/debian-packages-bench.txt")
"$root/scripts/install-deps.sh" "${lists[@]}"
source "$root/scripts/common.sh"
relight_build default
exec "$root/build/release/bench/relight-bench" "$@"
