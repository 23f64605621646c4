// Fuzzes the depth-image loader (core/image_io.h, read_depth_png): the input is the PNG file a
// TUM folder or `relight record` would hold. relight::Error is the answer to a corrupt, truncated
// or wrong-kind image; any other exception, a crash or a sanitizer report is a finding. A decoded
// image must hold only depths the 16-bit format can express.
#include <cmath>

#include "fuzz_input.h"
#include "image_size_limit.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr double kTumScale = 5000.0;
  const auto file = relight::fuzz::scratch().write("depth.png", relight::fuzz::as_text(data, size));
  try {
    const relight::DepthMap depth = relight::read_depth_png(file, kTumScale);
    for (int row = 0; row < depth.height(); ++row) {
      for (const float metres : depth.row(row)) {
        if (!(metres >= 0.f && metres <= 65535.0 / kTumScale + 1e-3)) std::abort();
      }
    }
  } catch (const relight::Error&) {
  }
  return 0;
}
