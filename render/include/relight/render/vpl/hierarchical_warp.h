#pragma once
// Hierarchical warping (Clarberg, Jarosz, Akenine-Möller, Jensen, "Wavelet Importance Sampling",
// SIGGRAPH 2005, §4): importance sampling of a 2^k x 2^k map by descending its sum pyramid (mip
// chain). At each level a point (u, v) in [0, 1)^2 picks the left or right column of the 2x2
// children in proportion to their column sums, then the top or bottom child of that column, and is
// rescaled into the chosen part, so a stratified point set stays stratified over the map. This is
// how a reflective shadow map's VPLs are drawn in proportion to its importance (Knecht 2013,
// §5.2.3; Dachsbacher & Stamminger's RSM sampling).
//
// Reads:  a size x size row-major map of importance (finite, >= 0; subnormal values count as 0,
//         as on GPUs that flush them), size a power of two; points in [0, 1)^2.
// Writes: the pyramid (levels 0..k, level 0 = the map, level k = the total; parents sum their
//         children as (a + b) + (c + d) in float) and, per point, the chosen texel and its
//         probability importance / total. A zero-importance texel is never chosen.
//
// The arithmetic is specified to the operation (one float add, multiply or divide per step, no
// fused multiply-add) so that the Vulkan version (hierarchical_warp_vk.h) chooses the same texels
// for the same points; see warp() in hierarchical_warp.cpp and shaders/warp_descend.comp.
#include <cstdint>
#include <span>
#include <vector>

namespace relight::render {

struct WarpPoint {
  float u = 0.f;  ///< [0, 1): horizontal (column) coordinate
  float v = 0.f;  ///< [0, 1): vertical (row) coordinate
};

struct WarpedTexel {
  std::uint32_t x = 0;      ///< column
  std::uint32_t y = 0;      ///< row
  float probability = 0.f;  ///< importance(x, y) / total: the discrete probability of choosing it
};

class ImportancePyramid {
 public:
  /// Largest accepted side (the pyramid of a 8192^2 map holds 89 M floats).
  static constexpr int kMaxSize = 8192;

  /// Throws Error naming the problem when `size` is not a power of two in [1, kMaxSize],
  /// importance.size() != size * size, a value is negative or not finite, or the total overflows.
  ImportancePyramid(std::span<const float> importance, int size);

  [[nodiscard]] int size() const { return size_; }
  /// k + 1: level 0 is the map, level k the single total.
  [[nodiscard]] int levels() const { return static_cast<int>(offsets_.size()); }
  [[nodiscard]] float total() const { return sums_.back(); }
  /// (size >> level)^2 row-major sums.
  [[nodiscard]] std::span<const float> level(int level) const;
  /// All levels back to back, level 0 first: the layout the Vulkan version uses.
  [[nodiscard]] std::span<const float> data() const { return sums_; }

  /// The texel `point` warps to. Requires total() > 0 (LogicError otherwise).
  [[nodiscard]] WarpedTexel warp(WarpPoint point) const;

 private:
  int size_ = 0;
  std::vector<std::size_t> offsets_;
  std::vector<float> sums_;
};

/// One warped texel per point; empty when the map's total is 0 (nothing to sample).
[[nodiscard]] std::vector<WarpedTexel> warp_points(const ImportancePyramid& pyramid, std::span<const WarpPoint> points);

/// The Hammersley set of `count` points: ((i + 0.5) / count, radical inverse of i in base 2).
/// A fixed low-discrepancy set, so that a frame's VPLs do not flicker from random draws.
[[nodiscard]] std::vector<WarpPoint> hammersley_points(std::uint32_t count);

}  // namespace relight::render
