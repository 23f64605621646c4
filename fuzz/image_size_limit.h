#pragma once
// Included once by each fuzz target that decodes images: they decode images up to 4 Mpixels. The
// product's limit (core/image_io.h) lets 64 Mpixel probes through, which the fuzzer's 2 GiB would
// not hold beside the decoders' copies, and every large allocation slows the search down.
#include <cstdint>

#include "relight/core/image_io.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  relight::set_image_size_limit({4096, std::int64_t{1} << 22});
  return 0;
}
