#!/usr/bin/env bash
# Runs clang-tidy (.clang-tidy) over the C++ sources changed since BASE (default: the parent of
# HEAD; locally also the uncommitted changes), with the compile commands of build/debug, which
# must have been configured. Headers are checked through the sources that include them.
# Usage: scripts/tidy-check.sh [BASE]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
base="${1:-HEAD~1}"
if ! git rev-parse --verify --quiet "$base^{commit}" >/dev/null; then
  echo "tidy check: no commit $base to compare with; skipped"
  exit 0
fi
if [ ! -f build/debug/compile_commands.json ]; then
  echo "tidy check: build/debug/compile_commands.json is missing (cmake --preset debug)" >&2
  exit 1
fi
mapfile -t files < <(git diff --name-only --diff-filter=d "$base" -- '*.cpp' |
                     grep -v '^fuzz/' | while read -r f; do grep -q "\"file\": \"$root/$f\"" build/debug/compile_commands.json && echo "$f"; done)
if [ "${#files[@]}" = 0 ]; then
  echo "tidy check: no compiled C++ source changed since $base"
  exit 0
fi
echo "tidy check: ${#files[@]} sources changed since $base"
# GCC-only warning flags in the compile commands are not clang-tidy's business.
printf '%s\n' "${files[@]}" | xargs -P "$(nproc)" -n 1 clang-tidy -p build/debug --quiet \
  --extra-arg=-Wno-unknown-warning-option 2>&1 | grep -v '^[0-9]* warnings\? \(and [0-9]* errors\? \)\?generated' |
  { failed=0; while IFS= read -r line; do echo "$line"; [[ "$line" == *": error: "* ]] && failed=1; done; exit $failed; }
