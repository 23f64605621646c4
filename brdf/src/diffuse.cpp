#include "relight/brdf/diffuse.h"

#include <algorithm>

#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::brdf {

namespace {

float luminance(const Eigen::Vector3f& v) { return 0.2126f * v.x() + 0.7152f * v.y() + 0.0722f * v.z(); }

template <class Linear>
void estimate(int width, int height, Linear&& linear_at, const PositionMap& positions, const NormalMap& normals,
              const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  if (positions.width() != width || positions.height() != height || !positions.same_shape(normals)) {
    throw Error("brdf diffuse: colour, positions and normals must have the same size");
  }
  kd.resize(width, height);
  valid.resize(width, height);
  parallel_for_each_row(height, options.threads, [&](int r) {
    for (int c = 0; c < width; ++c) {
      kd(r, c) = {};
      valid(r, c) = 0;
      const Float3 p = positions(r, c), n = normals(r, c);
      if (!is_valid_normal(n) || !is_valid_depth(p.z)) continue;
      const Eigen::Vector3f colour = linear_at(r, c);
      if (luminance(colour) < options.min_brightness) continue;
      const Eigen::Vector3f d = diffuse_shading(lights, {p.x, p.y, p.z}, {n.x, n.y, n.z});
      if (luminance(d) < options.min_shading || d.minCoeff() <= 0.f) continue;
      const Eigen::Vector3f k = colour.cwiseQuotient(d).cwiseMax(0.f).cwiseMin(options.max_kd);
      kd(r, c) = {k.x(), k.y(), k.z()};
      valid(r, c) = 1;
    }
  });
}

}  // namespace

void estimate_diffuse(const ColorImage& color, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  estimate(
      color.width(), color.height(),
      [&](int r, int c) {
        const Rgb8 v = color(r, c);
        return Eigen::Vector3f(srgb8_to_linear(v.r), srgb8_to_linear(v.g), srgb8_to_linear(v.b));
      },
      positions, normals, lights, options, kd, valid);
}

void estimate_diffuse(const RadianceImage& linear, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  estimate(
      linear.width(), linear.height(),
      [&](int r, int c) {
        const Float3 v = linear(r, c);
        return Eigen::Vector3f(v.x, v.y, v.z);
      },
      positions, normals, lights, options, kd, valid);
}

}  // namespace relight::brdf
