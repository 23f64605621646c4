#include "relight/core/allocator_tuning.h"

#include <cstddef>  // defines __GLIBC__ (through features.h) before the test below

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace relight {

void keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
  // Setting either also turns off glibc's dynamic thresholds. Both are needed: with the mmap
  // threshold alone the heap's top is still trimmed (given back) after each frame.
  (void)mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  (void)mallopt(M_TRIM_THRESHOLD, 256 * 1024 * 1024);
#endif
}

}  // namespace relight
