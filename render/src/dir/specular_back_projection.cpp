#include "relight/render/dir/specular_back_projection.h"

#include <cmath>

#include "relight/core/error.h"

namespace relight::render {
namespace {

/// Where the camera sees `point` (x, y, 1), if its image shows that very point: inside the
/// image, and no real surface between the camera and it (the virtual objects are not in the
/// camera image).
Float3 camera_source(const Eigen::Vector3f& point, const RayTracer& tracer, const MrCamera& camera,
                     float depth_tolerance) {
  const Eigen::Vector3d local = camera.camera_to_world.inverse() * point.cast<double>();
  if (!(local.z() > 0.0)) return {};
  const PinholeIntrinsics& k = camera.intrinsics;
  const double x = k.fx * local.x() / local.z() + k.cx, y = k.fy * local.y() / local.z() + k.cy;
  if (!(x >= 0.0 && y >= 0.0 && x <= k.width - 1.0 && y <= k.height - 1.0)) return {};
  const Eigen::Vector3f centre = camera.camera_to_world.translation().cast<float>();
  const Eigen::Vector3f to_point = point - centre;
  const float distance = to_point.norm();
  if (tracer.occluded(Layer::Real, centre, to_point / distance, distance * (1.f - depth_tolerance))) return {};
  return {static_cast<float>(x), static_cast<float>(y), 1.f};
}

}  // namespace

SpecularBackProjection back_project(const SpecularGBuffers& specular, const RadianceImage& reflected_real,
                                    const RadianceImage& refracted_real, const RayTracer& tracer,
                                    const MrCamera& camera, float depth_tolerance) {
  const int width = specular.specular.width(), height = specular.specular.height();
  if (!reflected_real.same_shape(specular.specular) || !refracted_real.same_shape(specular.specular))
    throw Error("back_project: the specular G-buffers and their light differ in size");
  SpecularBackProjection out;
  out.specular = specular.specular;
  const auto branch = [&](const SpecularBranch& b, const RadianceImage& real) {
    BackProjectedBranch projected{b.weight, real, Image<Float3>(width, height)};
    for (int row = 0; row < height; ++row)
      for (int col = 0; col < width; ++col) {
        if (!specular.specular(row, col) || b.gbuffer.distance(row, col) == 0.f || b.gbuffer.virtual_surface(row, col))
          continue;
        const Float3& p = b.gbuffer.position(row, col);
        projected.camera_pixel(row, col) = camera_source({p.x, p.y, p.z}, tracer, camera, depth_tolerance);
      }
    return projected;
  };
  out.reflected = branch(specular.reflected, reflected_real);
  out.refracted = branch(specular.refracted, refracted_real);
  return out;
}

}  // namespace relight::render
