# Shared by run.sh, test.sh and bench.sh: configure and build one CMake preset.
# ccache makes repeated builds (and CI's fresh clones) incremental.
relight_build() {
  local preset="$1"
  local root
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  export CCACHE_BASEDIR="$root"
  export CCACHE_NOHASHDIR=1
  cd "$root"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" --parallel "$(nproc)"
}
