#!/usr/bin/env bash
# Checks that the C++ lines changed since BASE (default: the parent of HEAD, i.e. the
# last commit; locally also the uncommitted changes) follow .clang-format. Only the changed lines
# are held to it (git clang-format), so older code is reformatted when it is next touched.
# Usage: scripts/format-check.sh [BASE]     Fix: git clang-format BASE
set -euo pipefail
check_name="format check"
# shellcheck source=scripts/lint-base.sh
source "$(dirname "${BASH_SOURCE[0]}")/lint-base.sh"
diff="$(git clang-format --diff --extensions cpp,h "$base" -- . || true)"
if [ -z "$diff" ] || [ "$diff" = "no modified files to format" ] || [[ "$diff" == *"did not modify any files"* ]]; then
  echo "format check: the lines changed since $base follow .clang-format"
  exit 0
fi
echo "$diff"
echo "format check: the lines above (changed since $base) do not follow .clang-format; run: git clang-format $base" >&2
exit 1
