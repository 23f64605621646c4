#include "relight/render/dir/specular_back_projection.h"

#include <cmath>

#include "relight/core/error.h"

namespace relight::render {
namespace {

/// Where the camera sees `point` (x, y, 1), if it sees that very point: inside the image, and
/// the primary G-buffer's real surface there at the point's distance.
Float3 camera_source(const Eigen::Vector3f& point, const GBuffer& primary, const MrCamera& camera,
                     float depth_tolerance) {
  const Eigen::Vector3d local = camera.camera_to_world.inverse() * point.cast<double>();
  if (!(local.z() > 0.0)) return {};
  const PinholeIntrinsics& k = camera.intrinsics;
  const double x = k.fx * local.x() / local.z() + k.cx, y = k.fy * local.y() / local.z() + k.cy;
  if (!(x >= 0.0 && y >= 0.0 && x <= k.width - 1.0 && y <= k.height - 1.0)) return {};
  const int col = static_cast<int>(std::lround(x)), row = static_cast<int>(std::lround(y));
  const float seen = primary.distance(row, col);
  if (seen == 0.f || primary.virtual_surface(row, col)) return {};
  const auto distance = static_cast<float>(local.norm());
  if (std::abs(seen - distance) > depth_tolerance * distance) return {};
  return {static_cast<float>(x), static_cast<float>(y), 1.f};
}

}  // namespace

SpecularBackProjection back_project(const SpecularGBuffers& specular, const RadianceImage& reflected_real,
                                    const RadianceImage& refracted_real, const GBuffer& primary, const MrCamera& camera,
                                    float depth_tolerance) {
  const int width = specular.specular.width(), height = specular.specular.height();
  if (!primary.distance.same_shape(specular.specular) || !reflected_real.same_shape(specular.specular) ||
      !refracted_real.same_shape(specular.specular))
    throw Error("back_project: the specular G-buffers, their light and the primary G-buffer differ in size");
  SpecularBackProjection out;
  out.specular = specular.specular;
  const auto branch = [&](const SpecularBranch& b, const RadianceImage& real) {
    BackProjectedBranch projected{b.weight, real, Image<Float3>(width, height)};
    for (int row = 0; row < height; ++row)
      for (int col = 0; col < width; ++col) {
        if (!specular.specular(row, col) || b.gbuffer.distance(row, col) == 0.f || b.gbuffer.virtual_surface(row, col))
          continue;
        const Float3& p = b.gbuffer.position(row, col);
        projected.camera_pixel(row, col) = camera_source({p.x, p.y, p.z}, primary, camera, depth_tolerance);
      }
    return projected;
  };
  out.reflected = branch(specular.reflected, reflected_real);
  out.refracted = branch(specular.refracted, refracted_real);
  return out;
}

}  // namespace relight::render
