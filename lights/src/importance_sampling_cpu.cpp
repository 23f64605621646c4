// CPU reference of hierarchical-warping importance sampling (definition in importance_sampling.h).
// The float operations mirror shaders/importance_pyramid.comp and importance_warp.comp one for
// one (same order, no fused multiply-add), so that both backends pick the same pixels.
#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "relight/core/error.h"
#include "relight/lights/importance_sampling.h"
#include "relight/lights/importance_shared.h"

namespace relight::lights {

namespace {

float non_negative(float value) { return value > 0.f ? value : 0.f; }  // NaN -> 0

// splitmix64: a well-mixed 64-bit value per seed, whose top 24 bits give an exact float.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

float keep_below_one(float value) {
  return std::min(value, static_cast<float>(RELIGHT_IMPORTANCE_ONE_MINUS_EPS));
}

// Picks the first half with probability first / (first + second) and rescales `coordinate` to
// [0, 1) inside the chosen half. Returns true for the second half.
bool warp_binary(float first, float second, float& coordinate) {
  const float scaled = coordinate * (first + second);
  if (scaled < first || !(second > 0.f)) {
    coordinate = keep_below_one(scaled / first);
    return false;
  }
  coordinate = keep_below_one((scaled - first) / second);
  return true;
}

// A point of an edge pixel may lie just outside the image circle: it is pulled onto the circle
// (as the shader clamps theta), keeping its azimuth.
Eigen::Vector3d sample_direction(const ProbeGeometry& geometry, double u, double v) {
  if (const auto direction = geometry.direction(u, v)) return *direction;
  const FisheyeCamera& fisheye = geometry.calibration().fisheye;
  const double du = u - fisheye.cx, dv = v - fisheye.cy;
  const double shrink = fisheye.radius / std::hypot(du, dv) * (1.0 - 1e-9);
  return geometry.direction(fisheye.cx + du * shrink, fisheye.cy + dv * shrink).value_or(Eigen::Vector3d::UnitZ());
}

}  // namespace

int pyramid_levels(int width, int height) {
  const auto edge = std::bit_ceil(static_cast<unsigned>(std::max({width, height, 1})));
  return std::countr_zero(edge);
}

std::size_t pyramid_floats(int levels) {
  std::size_t count = 0;
  for (int level = 0; level <= levels; ++level) {
    const std::size_t edge = std::size_t{1} << (levels - level);
    count += edge * edge;
  }
  return count;
}

float pixel_importance(const Float3& radiance, float solid_angle) {
  const float lum = 0.2126f * non_negative(radiance.x) + 0.7152f * non_negative(radiance.y) +
                    0.0722f * non_negative(radiance.z);
  return lum * solid_angle;
}

void ImportancePyramid::build(const RadianceImage& probe, const ProbeGeometry& geometry) {
  if (!probe.same_shape(geometry)) {
    throw Error("light probe: image is " + std::to_string(probe.width()) + "x" + std::to_string(probe.height()) +
                " but its calibration is for " + std::to_string(geometry.width()) + "x" +
                std::to_string(geometry.height()));
  }
  levels_ = pyramid_levels(probe.width(), probe.height());
  if (levels_ >= RELIGHT_IMPORTANCE_MAX_LEVELS) throw Error("light probe: image too large for the pyramid");
  offsets_.assign(static_cast<std::size_t>(levels_) + 1, 0);
  for (int level = 1; level <= levels_; ++level) {
    const std::size_t below = std::size_t{1} << (levels_ - level + 1);
    offsets_[static_cast<std::size_t>(level)] = offsets_[static_cast<std::size_t>(level) - 1] + below * below;
  }
  values_.assign(pyramid_floats(levels_), 0.f);

  const int edge = finest_size();
  for (int row = 0; row < probe.height(); ++row) {
    for (int col = 0; col < probe.width(); ++col) {
      values_[static_cast<std::size_t>(row) * static_cast<std::size_t>(edge) + static_cast<std::size_t>(col)] =
          pixel_importance(probe(row, col), geometry.solid_angle(row, col));
    }
  }
  for (int level = 1; level <= levels_; ++level) {
    const int size = edge >> level;
    const float* below = values_.data() + level_offset(level - 1);
    float* here = values_.data() + level_offset(level);
    const auto below_size = static_cast<std::size_t>(2 * size);
    for (int row = 0; row < size; ++row) {
      for (int col = 0; col < size; ++col) {
        const std::size_t top_left = 2 * static_cast<std::size_t>(row) * below_size + 2 * static_cast<std::size_t>(col);
        const float a = below[top_left], b = below[top_left + 1];
        const float c = below[top_left + below_size], d = below[top_left + below_size + 1];
        here[static_cast<std::size_t>(row) * static_cast<std::size_t>(size) + static_cast<std::size_t>(col)] =
            (a + b) + (c + d);
      }
    }
  }
}

float ImportancePyramid::at(int level, int row, int col) const {
  const std::size_t size = std::size_t{1} << (levels_ - level);
  return values_[level_offset(level) + static_cast<std::size_t>(row) * size + static_cast<std::size_t>(col)];
}

std::array<float, 2> seed_offsets(std::uint64_t seed) {
  if (seed == 0) return {0.f, 0.f};
  const std::uint64_t bits = mix(seed);
  constexpr float kToUnit = 1.f / 16777216.f;  // 2^-24: 24-bit integers convert exactly
  return {static_cast<float>(bits >> 40) * kToUnit, static_cast<float>((bits >> 8) & 0xffffffu) * kToUnit};
}

std::array<float, 2> hammersley_point(std::uint32_t i, float inverse_samples, float offset_u, float offset_v) {
  std::uint32_t reversed = i;
  reversed = ((reversed >> 1) & 0x55555555u) | ((reversed & 0x55555555u) << 1);
  reversed = ((reversed >> 2) & 0x33333333u) | ((reversed & 0x33333333u) << 2);
  reversed = ((reversed >> 4) & 0x0f0f0f0fu) | ((reversed & 0x0f0f0f0fu) << 4);
  reversed = ((reversed >> 8) & 0x00ff00ffu) | ((reversed & 0x00ff00ffu) << 8);
  reversed = (reversed >> 16) | (reversed << 16);
  const float radical = static_cast<float>(reversed >> 8) * (1.f / 16777216.f);
  const float u = (static_cast<float>(i) + 0.5f) * inverse_samples + offset_u;
  const float v = radical + offset_v;
  return {keep_below_one(u - std::floor(u)), keep_below_one(v - std::floor(v))};
}

WarpedSample warp_point(const ImportancePyramid& pyramid, int probe_width, std::array<float, 2> point) {
  float u = point[0], v = point[1];
  int col = 0, row = 0;
  for (int level = pyramid.levels(); level >= 1; --level) {
    const int below = level - 1;
    const float top_left = pyramid.at(below, 2 * row, 2 * col), top_right = pyramid.at(below, 2 * row, 2 * col + 1);
    const float bottom_left = pyramid.at(below, 2 * row + 1, 2 * col);
    const float bottom_right = pyramid.at(below, 2 * row + 1, 2 * col + 1);
    const bool right = warp_binary(top_left + bottom_left, top_right + bottom_right, u);
    col = 2 * col + (right ? 1 : 0);
    const bool bottom = right ? warp_binary(top_right, bottom_right, v) : warp_binary(top_left, bottom_left, v);
    row = 2 * row + (bottom ? 1 : 0);
  }
  return {static_cast<std::uint32_t>(row * probe_width + col), u, v};
}

LightSet sample_importance(const RadianceImage& probe, const ProbeGeometry& geometry,
                           const ImportanceSamplingOptions& options, ImportancePyramid& pyramid,
                           std::vector<WarpedSample>* samples_out) {
  if (options.samples <= 0) throw Error("light sampling: the number of lights must be positive");
  pyramid.build(probe, geometry);
  const float total = pyramid.total();
  if (!(total > 0.f) || !std::isfinite(total)) {
    throw Error("light probe: no light to sample (the image is black or not finite inside the image circle)");
  }
  const auto n = static_cast<std::uint32_t>(options.samples);
  const float inverse_samples = 1.f / static_cast<float>(n);
  const auto [offset_u, offset_v] = seed_offsets(options.seed);

  LightSet set;
  set.lights.reserve(n);
  if (samples_out) samples_out->clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    const WarpedSample sample =
        warp_point(pyramid, probe.width(), hammersley_point(i, inverse_samples, offset_u, offset_v));
    if (samples_out) samples_out->push_back(sample);
    const int row = static_cast<int>(sample.pixel) / probe.width();
    const int col = static_cast<int>(sample.pixel) % probe.width();
    const float omega = geometry.solid_angle(row, col);
    const float weight = pyramid.at(0, row, col);
    const Float3& radiance = probe(row, col);
    // L * omega / (N * w / W): this pixel's share of the probe's radiance, see the header.
    const double scale = static_cast<double>(omega) * total / (static_cast<double>(weight) * n);
    Light light;
    light.direction = sample_direction(geometry, col + sample.u - 0.5, row + sample.v - 0.5);
    light.power = scale * Eigen::Vector3d(non_negative(radiance.x), non_negative(radiance.y), non_negative(radiance.z));
    set.lights.push_back(light);
  }
  return set;
}

LightSet sample_importance(const RadianceImage& probe, const ProbeGeometry& geometry,
                           const ImportanceSamplingOptions& options) {
  ImportancePyramid pyramid;
  return sample_importance(probe, geometry, options, pyramid);
}

}  // namespace relight::lights
