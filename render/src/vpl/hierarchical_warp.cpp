// Hierarchical warping on the CPU (definition in hierarchical_warp.h); shaders/warp_pyramid.comp
// and shaders/warp_descend.comp repeat these steps operation for operation.
#include "relight/render/vpl/hierarchical_warp.h"

#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "relight/core/error.h"

namespace relight::render {
namespace {

/// The largest float below 1: rescaled coordinates stay in [0, 1) despite rounding.
constexpr float kBelowOne = 0x1.fffffep-1f;

std::uint32_t reverse_bits(std::uint32_t x) {
  x = (x << 16u) | (x >> 16u);
  x = ((x & 0x00ff00ffu) << 8u) | ((x & 0xff00ff00u) >> 8u);
  x = ((x & 0x0f0f0f0fu) << 4u) | ((x & 0xf0f0f0f0u) >> 4u);
  x = ((x & 0x33333333u) << 2u) | ((x & 0xccccccccu) >> 2u);
  return ((x & 0x55555555u) << 1u) | ((x & 0xaaaaaaaau) >> 1u);
}

float flush_subnormal(float value) { return value < std::numeric_limits<float>::min() ? 0.f : value; }

/// Picks the first of two parts with masses `first` and `second` for coordinate `x` in [0, 1) and
/// rescales x into the chosen part. A part without mass is never picked.
bool pick_first(float first, float second, float& x) {
  const float t = x * (first + second);
  const bool take_first = second == 0.f || (first > 0.f && t < first);
  const float rescaled = take_first ? t / first : (t - first) / second;
  x = std::fmin(rescaled, kBelowOne);
  return take_first;
}

}  // namespace

ImportancePyramid::ImportancePyramid(std::span<const float> importance, int size) : size_(size) {
  if (size < 1 || size > kMaxSize || !std::has_single_bit(static_cast<unsigned>(size)))
    throw Error("importance map: side " + std::to_string(size) + " is not a power of two in [1, " +
                std::to_string(kMaxSize) + "]");
  const auto n = static_cast<std::size_t>(size);
  if (importance.size() != n * n)
    throw Error("importance map: " + std::to_string(importance.size()) + " values for a " + std::to_string(size) + "^2 map");
  std::size_t total_texels = 0;
  for (std::size_t side = n; side >= 1; side /= 2) {
    offsets_.push_back(total_texels);
    total_texels += side * side;
  }
  sums_.resize(total_texels);
  for (std::size_t i = 0; i < importance.size(); ++i) {
    const float value = importance[i];
    if (!(value >= 0.f) || !std::isfinite(value))
      throw Error("importance map: texel " + std::to_string(i) + " is negative or not finite");
    sums_[i] = flush_subnormal(value);
  }
  for (std::size_t level = 1, side = n / 2; side >= 1; ++level, side /= 2) {
    const float* fine = sums_.data() + offsets_[level - 1];
    float* coarse = sums_.data() + offsets_[level];
    for (std::size_t y = 0; y < side; ++y)
      for (std::size_t x = 0; x < side; ++x) {
        const float* top = fine + 2 * y * 2 * side + 2 * x;
        const float* bottom = top + 2 * side;
        coarse[y * side + x] = (top[0] + top[1]) + (bottom[0] + bottom[1]);
      }
  }
  if (!std::isfinite(total())) throw Error("importance map: the total overflows a float");
}

std::span<const float> ImportancePyramid::level(int level) const {
  if (level < 0 || level >= levels()) throw LogicError("ImportancePyramid::level: no level " + std::to_string(level));
  const auto side = static_cast<std::size_t>(size_) >> level;
  return std::span(sums_).subspan(offsets_[static_cast<std::size_t>(level)], side * side);
}

WarpedTexel ImportancePyramid::warp(WarpPoint point) const {
  if (!(total() > 0.f)) throw LogicError("ImportancePyramid::warp: the map has no importance");
  float u = std::fmin(std::fmax(point.u, 0.f), kBelowOne);
  float v = std::fmin(std::fmax(point.v, 0.f), kBelowOne);
  std::uint32_t x = 0, y = 0;
  for (int child = levels() - 2; child >= 0; --child) {
    const auto side = static_cast<std::uint32_t>(size_) >> child;
    const float* sums = sums_.data() + offsets_[static_cast<std::size_t>(child)];
    const std::uint32_t cx = 2 * x, cy = 2 * y;
    const float a = sums[cy * side + cx], b = sums[cy * side + cx + 1];
    const float c = sums[(cy + 1) * side + cx], d = sums[(cy + 1) * side + cx + 1];
    const bool left = pick_first(a + c, b + d, u);
    x = left ? cx : cx + 1;
    y = pick_first(left ? a : b, left ? c : d, v) ? cy : cy + 1;
  }
  return {x, y, sums_[y * static_cast<std::uint32_t>(size_) + x] / total()};
}

std::vector<WarpedTexel> warp_points(const ImportancePyramid& pyramid, std::span<const WarpPoint> points) {
  std::vector<WarpedTexel> texels;
  if (!(pyramid.total() > 0.f)) return texels;
  texels.reserve(points.size());
  for (const WarpPoint& point : points) texels.push_back(pyramid.warp(point));
  return texels;
}

std::vector<WarpPoint> hammersley_points(std::uint32_t count) {
  std::vector<WarpPoint> points(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const double u = (static_cast<double>(i) + 0.5) / static_cast<double>(count);
    const double v = static_cast<double>(reverse_bits(i)) * 0x1p-32;
    points[i] = {static_cast<float>(u), std::fmin(static_cast<float>(v), kBelowOne)};
  }
  return points;
}

}  // namespace relight::render
