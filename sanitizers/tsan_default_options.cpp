// Linked into the programs of the tsan build only (cmake/Sanitizers.cmake). ThreadSanitizer asks
// for its default options before main, so every run of an instrumented program applies
// sanitizers/tsan.supp: a test binary run by hand, by gtest's test discovery during the build, by
// ctest, and the relight CLI that the app tests start. TSAN_OPTIONS still adds to these.
// halt_on_error: the first report fails the test that met it, as UBSan does in the asan build.
extern "C" const char* __tsan_default_options() {
  return "suppressions=" RELIGHT_TSAN_SUPPRESSIONS ":halt_on_error=1:second_deadlock_stack=1";
}
