#pragma once
// Materials: the frame-graph slot that BRDF estimation fills and the renderer reads for real
// surfaces: one Phong material per K-means cluster (parameters in the model of shading.h) and the
// map that says which cluster each camera pixel belongs to.
#include <Eigen/Core>
#include <vector>

#include "relight/core/image.h"

namespace relight::brdf {

struct MaterialParams {
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();  ///< diffuse albedo, linear RGB (the cluster centre)
  float ks = 0.f;                                ///< scalar specular coefficient (white highlights); 0 = diffuse
  float n = 1.f;                                 ///< Phong exponent
  int pixels = 0;                                ///< camera pixels in the cluster this frame
  /// RMS radiance residual of the specular fit over the cluster's samples (-1: not fitted).
  float fit_rms = -1.f;
};

struct Materials {
  static constexpr const char* type_name = "Materials";
  std::vector<MaterialParams> clusters;
  /// Cluster index + 1 per camera pixel; 0 = no material (no valid k_d there).
  LabelImage ids;
};

}  // namespace relight::brdf
