#pragma once
// Hierarchical-warping importance sampling of a light probe into N virtual point lights (VPLs).
//
// Clarberg, Jarosz, Akenine-Moeller, Jensen, "Wavelet Importance Sampling: Efficiently
// Evaluating Products of Complex Functions", SIGGRAPH 2005, section 4 (the mip-map warping that
// Knecht's dissertation, section 5.2.7, uses for the environment light source):
//  1. importance w(pixel) = luminance(L) * solid_angle(pixel), zero-padded to 2^L x 2^L, and its
//     sum pyramid (level 0 the finest, level L one value: the total W);
//  2. N stratified points (Hammersley, Cranley-Patterson rotated by the seed) are warped from the
//     top: at each 2x2 node a point picks the left/right column with probability proportional
//     to the column sums and is rescaled to [0, 1), then the row inside that column likewise;
//  3. the leaf pixel and the remaining (u, v) give a direction; its pdf over directions is
//     p = w / (W * solid_angle), so the VPL's RGB irradiance is L * omega / (N * p_pixel)
//     = L * solid_angle * W / (N * w). With this weighting sum_i power_i * max(0, n.d_i) is an
//     unbiased estimate of the probe's irradiance on a surface of normal n.
// Warping preserves stratification, and a fixed seed reuses the same points every frame, so a
// static probe gives the same VPLs (temporal stability, see light_smoothing.h).
//
// Both backends compute the same float operations in the same order (luminance, 2x2 sums
// (a + b) + (c + d), the warp), so they pick the same pixels for the same seed.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "relight/core/image.h"
#include "relight/lights/light_set.h"
#include "relight/lights/probe_geometry.h"

namespace relight::vk {
class VulkanContext;
}  // namespace relight::vk

namespace relight::lights {

struct ImportanceSamplingOptions {
  int samples = 64;        ///< N
  std::uint64_t seed = 0;  ///< rotation of the point set; same seed, same VPLs
};

/// The importance sum pyramid of step 1. Rebuilt per frame; keeps its allocation.
class ImportancePyramid {
 public:
  void build(const RadianceImage& probe, const ProbeGeometry& geometry);
  [[nodiscard]] int levels() const { return levels_; }
  [[nodiscard]] int finest_size() const { return 1 << levels_; }
  [[nodiscard]] std::size_t level_offset(int level) const { return offsets_[static_cast<std::size_t>(level)]; }
  [[nodiscard]] float at(int level, int row, int col) const;
  /// W: the sum of every pixel's importance (the top of the pyramid).
  [[nodiscard]] float total() const { return values_.back(); }
  [[nodiscard]] const std::vector<float>& values() const { return values_; }

 private:
  int levels_ = 0;
  std::vector<std::size_t> offsets_;
  std::vector<float> values_;
};

/// The pyramid's levels and the offsets of each level (finest first) for a width x height probe.
[[nodiscard]] int pyramid_levels(int width, int height);
[[nodiscard]] std::size_t pyramid_floats(int levels);

/// Importance of one probe pixel: Rec. 709 luminance of the (non-negative) radiance times the
/// solid angle, in float exactly as the shader computes it.
[[nodiscard]] float pixel_importance(const Float3& radiance, float solid_angle);

/// Sample i of the N-point rotated Hammersley set in [0, 1)^2.
[[nodiscard]] std::array<float, 2> hammersley_point(std::uint32_t i, float inverse_samples, float offset_u,
                                                    float offset_v);
/// The Cranley-Patterson offsets for a seed (0 for seed 0).
[[nodiscard]] std::array<float, 2> seed_offsets(std::uint64_t seed);

/// Where one point landed: the probe pixel and the position inside it, [0, 1)^2.
struct WarpedSample {
  std::uint32_t pixel = 0;  ///< row * width + col
  float u = 0.f;
  float v = 0.f;
  friend bool operator==(const WarpedSample&, const WarpedSample&) = default;
};

/// Step 2 for one point. The pyramid's total must be positive.
[[nodiscard]] WarpedSample warp_point(const ImportancePyramid& pyramid, int probe_width, std::array<float, 2> point);

/// The CPU reference: steps 1-3. Throws relight::Error when the probe is black (nothing to
/// sample) or its size does not match the geometry. `samples_out`, when given, gets the warped
/// samples in sequence order (the lights are in the same order).
[[nodiscard]] LightSet sample_importance(const RadianceImage& probe, const ProbeGeometry& geometry,
                                         const ImportanceSamplingOptions& options, ImportancePyramid& pyramid,
                                         std::vector<WarpedSample>* samples_out = nullptr);
[[nodiscard]] LightSet sample_importance(const RadianceImage& probe, const ProbeGeometry& geometry,
                                         const ImportanceSamplingOptions& options);

/// The Vulkan version: pyramid and warp on the GPU (one submission). Holds the pipelines and
/// the probe's geometry on the device; create it once per probe size and reuse it.
class ImportanceSamplerVk {
 public:
  ImportanceSamplerVk(vk::VulkanContext& context, const ProbeGeometry& geometry);
  ~ImportanceSamplerVk();
  ImportanceSamplerVk(const ImportanceSamplerVk&) = delete;
  ImportanceSamplerVk& operator=(const ImportanceSamplerVk&) = delete;

  /// Uploads the probe, samples, downloads the VPLs (same contract as sample_importance).
  [[nodiscard]] LightSet run(const RadianceImage& probe, const ImportanceSamplingOptions& options,
                             std::vector<WarpedSample>* samples_out = nullptr);
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Resources;
  vk::VulkanContext& context_;
  ProbeGeometry geometry_;
  std::unique_ptr<Resources> resources_;
  std::optional<double> last_gpu_ms_;
};

}  // namespace relight::lights
