#pragma once
// Depth as OpenNI devices deliver it (ONI_PIXEL_FORMAT_DEPTH_1_MM): uint16 millimetres, 0 = no
// measurement. One rounding rule shared by our OpenNI2 driver (metres -> mm) and the readers
// (mm -> metres), so that a test can predict the driver's pixels exactly from synth's depth.
#include <cmath>
#include <cstdint>

#include "relight/core/pixel.h"

namespace relight::capture {

/// Nearest millimetre; invalid or non-positive depth -> 0; beyond 65.535 m -> 0 (out of range).
[[nodiscard]] inline std::uint16_t depth_to_millimetres(float metres) {
  if (!is_valid_depth(metres)) return 0;
  const double mm = std::round(static_cast<double>(metres) * 1000.0);
  return mm > 65535.0 ? std::uint16_t{0} : static_cast<std::uint16_t>(mm);
}

[[nodiscard]] inline float millimetres_to_depth(std::uint16_t mm) { return static_cast<float>(mm) / 1000.0f; }

}  // namespace relight::capture
