#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, the fuzz preset: clang, ASan + UBSan, build/fuzz) and runs
# each for SECONDS (default 60) on its seed inputs (fuzz/corpus/<target>/) plus what earlier runs
# found (build/fuzz/corpus/<target>/, kept between runs so that longer runs build on each other).
# Prints executions and crashes per target; a crashing input is kept under
# build/fuzz/crashes/<target>/ and the script exits 1 (add the input to fuzz/corpus/<target>/ as a
# regression once the product is fixed).
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   (targets: tum_lists json_config depth_png obj gltf
# tag_layout lights_json probe_image probe_list)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(tum_lists json_config depth_png obj gltf tag_layout lights_json probe_image probe_list)

source "$root/scripts/common.sh"
export CC=clang CXX=clang++
relight_build fuzz

build="$root/build/fuzz"
failed=0
printf '%-12s %8s %12s %10s %8s  %s\n' target seconds executions exec/s corpus result
for target in "${targets[@]}"; do
  binary="$build/fuzz/${target}_fuzzer"
  [ -x "$binary" ] || { echo "error: no fuzz target '$target' ($binary)" >&2; exit 2; }
  found="$build/corpus/$target"
  crashes="$build/crashes/$target"
  log="$build/logs/$target.log"
  report="$build/logs/$target.sanitizer"
  mkdir -p "$found" "$crashes" "$(dirname "$log")"
  rm -f "$report".*
  # One input may take at most 10 s and 2 GiB; more is a finding (a hang or an allocation a
  # malformed file can trigger), as a crash is. Sanitizer reports go to their own file: the image
  # readers mute stderr while a decoder runs, which would swallow a report from inside it.
  status=0
  ASAN_OPTIONS="log_path=$report" UBSAN_OPTIONS="log_path=$report:print_stacktrace=1" \
    "$binary" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$crashes/" "$found" "$root/fuzz/corpus/$target" >"$log" 2>&1 || status=$?
  executions="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  corpus="$(find "$found" "$root/fuzz/corpus/$target" -type f | wc -l)"
  result="ok"
  if [ "$status" -ne 0 ]; then
    failed=1
    result="CRASH ($(ls -t "$crashes" | head -1)), log: $log"
  fi
  printf '%-12s %8s %12s %10s %8s  %s\n' "$target" "$seconds" "${executions:-?}" "${rate:-?}" "$corpus" "$result"
  if [ "$status" -ne 0 ]; then
    grep -h -E -m1 -A14 "^==[0-9]+== ?ERROR|runtime error|deadly signal|uncaught exception" "$report".* "$log" 2>/dev/null ||
      tail -20 "$log"
  fi
done
exit "$failed"
