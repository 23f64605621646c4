#!/usr/bin/env bash
# Runs clang-tidy (.clang-tidy) over the lines of C++ sources changed since BASE (default: the
# parent of HEAD; locally also the uncommitted changes), with the compile commands of
# build/debug, which must have been configured. Like the format check, only the changed lines are
# held to it (clang-tidy-diff), so older code is cleaned up when it is next touched. Sources
# outside the compile commands (fuzz targets, the install test's consumer) are not checked.
# Usage: scripts/tidy-check.sh [BASE]
set -euo pipefail
check_name="tidy check"
# shellcheck source=scripts/lint-base.sh
source "$(dirname "${BASH_SOURCE[0]}")/lint-base.sh"
database=build/debug/compile_commands.json
if [ ! -f "$database" ]; then
  echo "tidy check: $database is missing (cmake --preset debug)" >&2
  exit 1
fi
mapfile -t files < <(git diff --name-only --diff-filter=d "$base" -- '*.cpp' |
                     while read -r f; do if grep -qF "\"file\": \"$root/$f\"" "$database"; then echo "$f"; fi; done)
if [ "${#files[@]}" = 0 ]; then
  echo "tidy check: no compiled C++ source changed since $base"
  exit 0
fi
# GCC-only warning flags in the compile commands are not clang-tidy's business.
output="$(git diff -U0 "$base" -- "${files[@]}" |
          clang-tidy-diff -p1 -path build/debug -j "$(nproc)" -quiet -extra-arg=-Wno-unknown-warning-option 2>&1 |
          grep -v '^[0-9]* warnings\? \(and [0-9]* errors\? \)\?generated' || true)"
if grep -q ": error: " <<<"$output"; then
  echo "$output"
  echo "tidy check: clang-tidy found the problems above in lines changed since $base" >&2
  exit 1
fi
echo "tidy check: the lines changed since $base in ${#files[@]} sources pass clang-tidy"
