#include "relight/core/parallel.h"
#include "relight/render/dir/gbuffer.h"

namespace relight::render {

GBuffer gbuffer_cpu(const RayTracer& tracer, const MrCamera& camera, int threads) {
  const PinholeIntrinsics& k = camera.intrinsics;
  GBuffer out{PositionMap(k.width, k.height), NormalMap(k.width, k.height), LabelImage(k.width, k.height),
              Mask(k.width, k.height), DepthMap(k.width, k.height)};
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  parallel_rows(k.height, threads, [&](int begin, int end) {
    for (int row = begin; row < end; ++row)
      for (int col = 0; col < k.width; ++col) {
        const Eigen::Vector3f d = (camera.camera_to_world.linear() * k.ray(col, row).normalized()).cast<float>();
        const auto real = tracer.intersect(Layer::Real, origin, d);
        const auto virtual_hit =
            tracer.intersect(Layer::Virtual, origin, d, real ? real->t : std::numeric_limits<float>::infinity());
        const auto& hit = virtual_hit ? virtual_hit : real;
        if (!hit) continue;
        Eigen::Vector3f n = hit->shading_normal;
        if (n.dot(d) > 0.f) n = -n;
        out.position(row, col) = {hit->point.x(), hit->point.y(), hit->point.z()};
        out.normal(row, col) = {n.x(), n.y(), n.z()};
        out.material(row, col) = static_cast<std::uint16_t>(hit->material + 1);
        out.virtual_surface(row, col) = hit->real ? 0 : 1;
        out.distance(row, col) = hit->t;
      }
  }, 4);
  return out;
}

}  // namespace relight::render
