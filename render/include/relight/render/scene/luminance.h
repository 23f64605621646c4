#pragma once
// The relative luminance Y of a linear sRGB (Rec. 709) colour held as an Eigen vector: the
// renderers' weight for choosing among lights, lobes and VPLs by brightness (core/pixel.h has
// the same for Float3).
#include <Eigen/Core>

namespace relight::render {

[[nodiscard]] inline float luminance(const Eigen::Vector3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

}  // namespace relight::render
