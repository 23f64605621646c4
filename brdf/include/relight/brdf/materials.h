#pragma once
// Materials: the frame-graph slot that BRDF estimation fills and the renderer reads for real
// surfaces: one Phong material per K-means cluster (parameters in the model of shading.h) and the
// map that says which cluster each camera pixel belongs to.
#include <Eigen/Core>
#include <vector>

#include "relight/core/image.h"
#include "relight/core/phong.h"

namespace relight::brdf {

/// A cluster's Phong material (core/phong.h): k_d is the cluster centre (linear RGB), k_s = 0 a
/// diffuse cluster.
struct MaterialParams : Phong {
  int pixels = 0;  ///< camera pixels in the cluster this frame
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
