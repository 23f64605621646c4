#!/usr/bin/env bash
# Installs what is missing, checks the format and clang-tidy of the last commit's changes, builds
# (optimised, with assertions) and runs every test CI runs, then runs the unit tests below the
# renderer under AddressSanitizer + UndefinedBehaviorSanitizer, the tests that start threads under
# ThreadSanitizer, a short run of every fuzz target, the tests of render, app, pipeline and
# robustness under AddressSanitizer + UndefinedBehaviorSanitizer, and compiles the Release+tests
# combination; the last two within the time left (RELIGHT_CI_SECONDS).
# Usage: scripts/test.sh [extra ctest arguments for the main suite, e.g. -L core]
# RELIGHT_ASAN=0 skips the sanitizer stage, RELIGHT_TSAN=0 the thread sanitizer stage,
# RELIGHT_FUZZ_SECONDS=0 the fuzzing stage,
# RELIGHT_RELEASE_BUILD=0 the Release+tests build, RELIGHT_LINT=0 the format and tidy checks;
# RELIGHT_CI_SECONDS (default 5100) is the whole run's time, which the Release build gives way
# to. Each stage prints its time.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
source "$root/scripts/common.sh"
if [ "${RELIGHT_LINT:-1}" != 0 ]; then
  "$root/scripts/format-check.sh"
fi
start=$SECONDS
relight_build debug
echo "build stage: $((SECONDS - start)) s"
if [ "${RELIGHT_LINT:-1}" != 0 ]; then
  start=$SECONDS
  "$root/scripts/tidy-check.sh"
  echo "tidy stage: $((SECONDS - start)) s"
fi
# The Vulkan tests run on whatever device the loader finds (lavapipe on machines without a GPU);
# RELIGHT_REQUIRE_VULKAN turns "no Vulkan device" into a failure instead of a skip.
export RELIGHT_REQUIRE_VULKAN="${RELIGHT_REQUIRE_VULKAN:-1}"
# RELIGHT_REQUIRE_VALIDATION does the same for the Vulkan validation layer (vulkan-validationlayers).
export RELIGHT_REQUIRE_VALIDATION="${RELIGHT_REQUIRE_VALIDATION:-1}"
start=$SECONDS
ctest --test-dir "$root/build/debug" --output-on-failure --parallel "$(nproc)" --timeout 600 -LE soak "$@"
# The soak label bounded: the record -> replay round trip over 100 live frames instead of 1 000.
RELIGHT_SOAK_FRAMES="${RELIGHT_SOAK_FRAMES:-100}" ctest --test-dir "$root/build/debug" --output-on-failure --timeout 600 -L soak
echo "test stage: $((SECONDS - start)) s"

# Seconds left of RELIGHT_CI_SECONDS (85 minutes: CI stops the run at 90). The stages after the
# fuzzing stage run only in what is left, so that a cold cache (every object compiled three more
# times: sanitizers, Release) makes CI skip them, saying so, instead of overrunning.
time_left() { echo $(( ${RELIGHT_CI_SECONDS:-5100} - SECONDS )); }

# AddressSanitizer + UndefinedBehaviorSanitizer (the asan preset, build/asan; suppressions and
# options in sanitizers/ and the presets; line tables only, -g1, which is what the reports use and
# a fifth less compile time than -g). First the unit tests of the labels below the renderer,
# reconstruct's SSE2/AVX2 kernels among them (AVX2 where the CPU has it, as here); MarkerPose.
# NoiseFreeSyntheticFrames... is left out there: its minutes go to synth's ray caster rendering
# 640x480 frames, which the synth label already runs under the sanitizers. OpenNI2's tests run
# with the slow unwinder: libOpenNI2 has no frame pointers, and only that unwinder reaches the
# caller that sanitizers/lsan.supp names (too slow for the rest: lavapipe allocates a lot).
# render and the tests that run the relight executable follow after the fuzzing stage.
if [ "${RELIGHT_ASAN:-1}" != 0 ]; then
  asan_labels='core|capture|synth|colormap|lights|brdf|reconstruct'
  asan_tests=(relight_core_tests relight_capture_tests relight_synth_tests relight_colormap_tests
              relight_lights_tests relight_brdf_tests relight_reconstruct_tests)
  start=$SECONDS
  cmake --preset asan >/dev/null
  cmake --build --preset asan --parallel "$(nproc)" --target "${asan_tests[@]}"
  ctest --preset asan --parallel "$(nproc)" --timeout 900 -L "$asan_labels" -LE soak \
    -E 'OpenNi|MarkerPose\.NoiseFreeSyntheticFrames'
  ASAN_OPTIONS=fast_unwind_on_malloc=0 ctest --preset asan --parallel "$(nproc)" --timeout 900 -L "$asan_labels" -R 'OpenNi'
  echo "sanitizer stage: $((SECONDS - start)) s"
fi

# ThreadSanitizer (the tsan preset, build/tsan; suppressions with their reasons in
# sanitizers/tsan.supp, read by the programs themselves): the tests whose code runs on several
# threads - the worker pool of the parallel loops, the write queue, the frame graph, the prefetching
# source, the OpenNI2 driver's frame thread and live capture from the synthetic device, method 2's
# banded warp and the other row-parallel reconstruct, brdf, colormap and synth stages, K-means, the
# path tracer, DIR on the CPU and caustic photons. Left out: the Vulkan twins (lavapipe's own
# threads, and 10-50 times slower), OpenNiDriver.ShortLoopRuns... (it measures the frame rate, which
# the sanitizer's slowdown breaks) and TemporalSmoothingStageTest (minutes of DIR frames; the
# smoothing's parallel rows are checked by TemporalSmoothing.ParallelRowsGiveTheSerialResult).
if [ "${RELIGHT_TSAN:-1}" != 0 ]; then
  tsan_tests=(relight_core_tests relight_capture_tests relight_reconstruct_tests relight_brdf_tests
              relight_synth_tests relight_colormap_tests render_tests)
  tsan_filter='ParallelRows|WorkerPool|WriteQueue|FrameGraph|PrefetchSource|OpenNi|SourceStage|DepthWarpMerge'
  tsan_filter+='|HierarchicalWarp|NormalsRawDepth|NormalsFromPositions|DepthWarp|KMeans\.|Highlight|Diffuse'
  tsan_filter+='|BrdfPreview|LightEstimation|Raycast|KinectNoise|CameraBlur|StatisticsTransfer\.|CameraLook'
  tsan_filter+='|DifferentialPathTracer|DirCpu|TemporalSmoothing|DirCaustics|EdgeCoverage|SpecularGBuffer'
  start=$SECONDS
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan --parallel "$(nproc)" --target "${tsan_tests[@]}"
  ctest --preset tsan --parallel "$(nproc)" --timeout 900 -LE soak -R "$tsan_filter" \
    -E 'Vk|Vulkan|OpenNiDriver\.ShortLoopRunsAtTheFrameRateOnceRendered|TemporalSmoothingStageTest'
  echo "thread sanitizer stage: $((SECONDS - start)) s"
fi

# Fuzzing: a short run of every libFuzzer target (scripts/fuzz.sh, build/fuzz); longer runs by
# hand with scripts/fuzz.sh SECONDS. Any crash fails CI and leaves its input in build/fuzz/crashes/.
fuzz_seconds="${RELIGHT_FUZZ_SECONDS:-30}"
if [ "$fuzz_seconds" != 0 ]; then
  start=$SECONDS
  "$root/scripts/fuzz.sh" "$fuzz_seconds"
  echo "fuzzing stage: $((SECONDS - start)) s"
fi

# AddressSanitizer + UndefinedBehaviorSanitizer over the rest: render's unit tests (Vulkan stages,
# path tracer, DIR) and the tests that run the relight executable (app, pipeline, robustness: the
# CLI, the whole graph, the fault rows) with the asan-cli preset's suppressions (sanitizers/
# lsan-cli.supp says why they differ). Their frames are as small as the tests already make them;
# on two cores no test takes more than 3.5 minutes under the sanitizers, the stage about 25 with
# its build cached, 40 without. It starts only with 25 minutes left and stops at the time limit
# (saying so; a test that fails before it fails CI).
if [ "${RELIGHT_ASAN:-1}" != 0 ]; then
  left=$(time_left)
  if [ "$left" -lt 1500 ]; then
    echo "sanitizer stage (render, app, pipeline, robustness): skipped, the run has ${left} s left of RELIGHT_CI_SECONDS"
  else
    start=$SECONDS
    status=0
    timeout "$((left - 60))" bash -c '
      set -euo pipefail
      cmake --build --preset asan --parallel "$(nproc)" --target render_tests relight relight_app_tests \
        relight_pipeline_tests relight_robustness_tests
      ctest --preset asan --parallel "$(nproc)" --timeout 900 -L render -LE soak
      ctest --preset asan-cli --parallel "$(nproc)" --timeout 900 -L "app|pipeline|robustness" -LE soak' || status=$?
    if [ "$status" = 124 ]; then
      echo "sanitizer stage (render, app, pipeline, robustness): stopped at the time limit after $((SECONDS - start)) s"
    elif [ "$status" != 0 ]; then
      exit "$status"
    else
      echo "sanitizer stage (render, app, pipeline, robustness): $((SECONDS - start)) s"
    fi
  fi
fi

# The Release (-O3) build with the tests, as packagers build it: only compiled, since -O3 brings
# warnings (GCC's flow analysis) that -O2 does not. It runs last and within a time budget: with a
# cold cache it takes about 20 minutes on two cores, so a run that hits the budget says so and
# leaves its objects in ccache for the next run, while any compile error or warning fails CI. The
# budget is 30 minutes, or what is left of RELIGHT_CI_SECONDS when that is less.
if [ "${RELIGHT_RELEASE_BUILD:-1}" != 0 ]; then
  start=$SECONDS
  budget="${RELIGHT_RELEASE_BUILD_SECONDS:-1800}"
  left=$(time_left)
  [ "$left" -lt "$budget" ] && budget=$left
  if [ "$budget" -lt 60 ]; then
    echo "release build stage: skipped, the run has ${left} s left of RELIGHT_CI_SECONDS"
  else
    export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=1
    cmake --preset release-tests >/dev/null
    status=0
    # ninja itself, so that the time limit stops the compilers too (ninja ends its jobs on SIGTERM)
    timeout "$budget" ninja -C "$root/build/release-tests" -j "$(nproc)" || status=$?
    if [ "$status" = 124 ]; then
      echo "release build stage: not finished within ${budget} s (its objects are cached for the next run)"
    elif [ "$status" != 0 ]; then
      exit "$status"
    fi
    echo "release build stage: $((SECONDS - start)) s"
  fi
fi
echo "scripts/test.sh: $SECONDS s in all"
