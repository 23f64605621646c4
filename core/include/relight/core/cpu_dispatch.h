#pragma once
// Function multi-versioning for hot loops, and the build facts it depends on.
//
// RELIGHT_AVX2_CLONES before a function compiles it for AVX2 and for the baseline x86-64; the
// loader picks one by the CPU (an ifunc). Under ThreadSanitizer (the tsan preset) it compiles the
// baseline version only: the loader runs an ifunc's resolver while it relocates the executable,
// before TSan's runtime is set up, and GCC instruments the resolver, so every test binary crashed
// before main (GCC 12). Races depend on which memory threads touch, which both versions share;
// the AVX2 versions run under ASan and in every other build.

#if defined(__SANITIZE_THREAD__)
#define RELIGHT_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define RELIGHT_THREAD_SANITIZER 1
#endif
#endif

#ifdef RELIGHT_THREAD_SANITIZER
#define RELIGHT_AVX2_CLONES
#else
#define RELIGHT_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#endif
