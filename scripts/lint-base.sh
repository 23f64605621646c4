# Sourced by scripts/format-check.sh and scripts/tidy-check.sh: the repository root as the working
# folder, and `base`, the commit whose changes are checked (argument 1; default the parent of
# HEAD). Exits the caller with 0 and a note when there is no such commit (a fresh clone with one
# commit, a shallow CI checkout): there is nothing to compare with.
# Usage (in a script): check_name="format check"; source "$(dirname "${BASH_SOURCE[0]}")/lint-base.sh"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
base="${1:-HEAD~1}"
if ! git rev-parse --verify --quiet "$base^{commit}" >/dev/null; then
  echo "$check_name: no commit $base to compare with; skipped"
  exit 0
fi
