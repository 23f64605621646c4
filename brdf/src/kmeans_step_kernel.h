#pragma once
// The inner loop of one Lloyd step on the CPU (KMeansCpu::step, kmeans.h): assign each point to
// its nearest centre and add its fixed-point colour, its count and its quantised squared distance
// to that cluster's sums. Private to relight_brdf.
//
// Two builds of the same arithmetic: an AVX2 one (8 points per instruction, picked at run time
// when the CPU has AVX2) and a portable one. Both evaluate every distance as
// ((dx*dx + dy*dy) + dz*dz) in float without fused multiply-add, break ties towards the lower
// index and quantise with truncation of value * scale + 0.5, exactly like brdf_kmeans.comp, so the
// CPU and Vulkan engines assign and sum identically.
#include <cstddef>
#include <cstdint>

#include "relight/brdf/kmeans.h"

namespace relight::brdf::detail {

/// Centres in structure-of-arrays form.
struct KMeansCentres {
  float x[RELIGHT_KMEANS_MAX_CLUSTERS];
  float y[RELIGHT_KMEANS_MAX_CLUSTERS];
  float z[RELIGHT_KMEANS_MAX_CLUSTERS];
  int count = 0;
};

/// Assigns points [0, count) of (x, y, z), writes their labels and adds to sums[0..centres.count);
/// `portable` forces the plain C++ build.
void kmeans_assign_and_sum(const float* x, const float* y, const float* z, std::size_t count,
                           const KMeansCentres& centres, std::uint8_t* labels, ClusterSums::Cluster* sums,
                           bool portable);

}  // namespace relight::brdf::detail
