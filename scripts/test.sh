#!/usr/bin/env bash
# Installs what is missing, builds (optimised, with assertions) and runs every test CI runs.
# Usage: scripts/test.sh [extra ctest arguments, e.g. -L core]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
source "$root/scripts/common.sh"
relight_build debug
# The Vulkan tests run on whatever device the loader finds (lavapipe on machines without a GPU);
# RELIGHT_REQUIRE_VULKAN turns "no Vulkan device" into a failure instead of a skip.
export RELIGHT_REQUIRE_VULKAN="${RELIGHT_REQUIRE_VULKAN:-1}"
# RELIGHT_REQUIRE_VALIDATION does the same for the Vulkan validation layer (vulkan-validationlayers).
export RELIGHT_REQUIRE_VALIDATION="${RELIGHT_REQUIRE_VALIDATION:-1}"
ctest --test-dir "$root/build/debug" --output-on-failure --parallel "$(nproc)" --timeout 600 -LE soak "$@"
