#pragma once
// The names of the BRDF estimation's own frame-graph buffers (buffer_name.h); core/buffers.h has
// its images (color_diffuse, highlight_mask, kd, kd_valid, brdf_preview).
#include "relight/brdf/kmeans.h"
#include "relight/brdf/materials.h"
#include "relight/core/buffer_name.h"

namespace relight::brdf {

inline constexpr BufferName<Materials> kMaterialClusters{"clusters"};  ///< K-means, k_d only
inline constexpr BufferName<Materials> kMaterials{"materials"};        ///< with the specular fit
/// K-means' state across frames (warm start from the last centres, the random restarts' generator),
/// a history the graph keeps: each frame continues from the previous frame's.
inline constexpr BufferName<KMeansTracker> kKMeansHistory{"kmeans_history"};

}  // namespace relight::brdf
