#pragma once
// The colour mapping tau of one frame as a frame-graph buffer ("color_mapping"), written by every
// mapping stage next to delta_L, so that later stages can map single radiance values exactly as
// the frame was mapped. The differential composite needs it where a virtual object covers the
// camera's view: there the picture is tau(TM(L_rv)) itself, not L_cam + delta_L (the camera shows
// the real surface behind the object, whose texture must not show through).
//   Matrix:      tau_sb(TM(c)) = A (TM(c), 1)             (sample_mapping.h; identity = none)
//   Statistics:  tau_st(TM(c)) = f^-1(tau_ct(f(TM(c))))   (statistics_transfer.h, eq. 4.30)
#include "relight/colormap/sample_mapping.h"
#include "relight/colormap/statistics_transfer.h"

namespace relight::colormap {

struct ColorMapping {
  static constexpr const char* type_name = "ColorMapping";
  enum class Kind { Matrix, Statistics };
  Kind kind = Kind::Matrix;
  ColorMatrix matrix = identity_color_matrix();  ///< Kind::Matrix
  ReinhardTransfer transfer;                     ///< Kind::Statistics
  ToneMap tone_map;

  [[nodiscard]] static ColorMapping of_matrix(const ColorMatrix& matrix, const ToneMap& tm) {
    return {Kind::Matrix, matrix, {}, tm};
  }
  [[nodiscard]] static ColorMapping of_statistics(const ReinhardTransfer& transfer, const ToneMap& tm) {
    return {Kind::Statistics, identity_color_matrix(), transfer, tm};
  }

  /// tau(TM(radiance)) in camera-linear sRGB (not clamped: the composite clamps once).
  [[nodiscard]] Float3 operator()(const Float3& radiance) const {
    if (kind == Kind::Statistics) return map_statistics(radiance, transfer, tone_map);
    const Float3 c = colormap::tone_map(radiance, tone_map);
    const Eigen::Vector3d mapped = apply(matrix, Eigen::Vector3d(c.x, c.y, c.z));
    return {static_cast<float>(mapped[0]), static_cast<float>(mapped[1]), static_cast<float>(mapped[2])};
  }
};

}  // namespace relight::colormap
