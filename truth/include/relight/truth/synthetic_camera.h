#pragma once
// A synthetic camera with a known colour transform, and L_r / L_rv / L_cam triples rendered from
// the synthetic scene: the ground truth of the colour-mapping tests and benchmarks.
//
// Camera model (applied to linear radiance L):
//   v = clamp(exposure * C * diag(gains) * L, 0, 1),  pixel = round(255 * v^(1/gamma)) [+ noise]
// gains: white-balance error; C: 3x3 channel crosstalk; gamma: a pure power curve, deliberately
// not the sRGB curve the mapping decodes with, so the camera is not exactly affine in the
// mapping's colour space.
#include <Eigen/Core>
#include <cstdint>

#include "relight/core/image.h"

namespace relight::truth {

struct CameraColorTransform {
  Eigen::Vector3d gains{1.0, 1.0, 1.0};
  Eigen::Matrix3d crosstalk = Eigen::Matrix3d::Identity();
  double exposure = 1.0;
  double gamma = 2.2;
  double noise_sigma = 0.0;  ///< Gaussian noise on the 8-bit value (in 8-bit units)
  std::uint64_t noise_seed = 0;

  /// The transform used by the tests: warm white balance (1.4, 1.0, 0.6) as under tungsten light,
  /// 10-16 % crosstalk, exposure 0.8, gamma 2.2.
  [[nodiscard]] static CameraColorTransform typical();
};

[[nodiscard]] ColorImage apply_camera(const RadianceImage& radiance, const CameraColorTransform& camera);

struct SyntheticTripleOptions {
  int width = 160;   ///< the Kinect intrinsics scaled to this size (keep 4:3)
  int height = 120;
  Eigen::Vector3d virtual_albedo{0.75, 0.40, 0.10};  ///< diffuse albedo of the virtual sphere
  double virtual_radius = 0.11;                      ///< sphere on the table, metres
  CameraColorTransform camera = CameraColorTransform::typical();
};

struct SyntheticTriple {
  RadianceImage real;          ///< L_r: radiance of the real scene
  RadianceImage real_virtual;  ///< L_rv: the same with a virtual sphere on the table
  ColorImage camera;           ///< L_cam: the camera's image of the real scene
  ColorImage truth;            ///< the camera's image of the scene with the sphere (the goal)
};
[[nodiscard]] SyntheticTriple make_synthetic_triple(const SyntheticTripleOptions& options = {});

/// Mean CIEDE2000 (Lab of the decoded 8-bit images, illuminant E) over the pixels of `mask`.
[[nodiscard]] double mean_delta_e(const ColorImage& first, const ColorImage& second, const Mask& mask);

}  // namespace relight::truth
