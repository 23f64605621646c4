#include "relight/render/dir/temporal_smoothing.h"

#include <algorithm>
#include <cmath>

#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::render {
namespace {

constexpr float kNear = 0.02f;  // gbuffer_vk.cpp's projection
constexpr float kFar = 200.f;

float saturate(float x) { return std::clamp(x, 0.f, 1.f); }

struct Reprojection {
  int col = 0, row = 0;
  Eigen::Vector3f screen_and_depth;  ///< (x / width, y / height, depth-buffer value)
};

/// Where world points land in a camera's image (its world-to-camera transform inverted once,
/// not per point: every pixel reprojects twice).
class Reprojector {
 public:
  explicit Reprojector(const MrCamera& camera)
      : world_to_camera_(camera.camera_to_world.inverse()), intrinsics_(camera.intrinsics) {}

  /// Where `world` lands, if inside the image and in front.
  [[nodiscard]] std::optional<Reprojection> operator()(const Eigen::Vector3f& world) const {
    const Eigen::Vector3d p = world_to_camera_ * world.cast<double>();
    if (p.z() <= kNear) return std::nullopt;
    const PinholeIntrinsics& k = intrinsics_;
    const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
    const int col = static_cast<int>(std::lround(u)), row = static_cast<int>(std::lround(v));
    if (col < 0 || row < 0 || col >= k.width || row >= k.height) return std::nullopt;
    return Reprojection{col,
                        row,
                        {static_cast<float>(u / k.width), static_cast<float>(v / k.height),
                         depth_buffer_value(static_cast<float>(p.z()))}};
  }

 private:
  Pose world_to_camera_;
  PinholeIntrinsics intrinsics_;
};

}  // namespace

float depth_buffer_value(float z) { return kFar / (kFar - kNear) * (1.f - kNear / z); }

TemporalHistory smooth_indirect(DifferentialImages& images, const GBuffer& gbuffer, const MrCamera& camera,
                                const TemporalHistory* previous, const TemporalOptions& options) {
  const int width = gbuffer.position.width(), height = gbuffer.position.height();
  if (images.indirect_real.width() != width || images.indirect_real.height() != height)
    throw LogicError("smooth_indirect: the images carry no indirect part of the G-buffer's size");
  if (previous && previous->positions.width() > 0) {
    const Reprojector reproject(previous->camera);
    // Each pixel reads the previous frame and writes only itself: rows are independent.
    parallel_rows(
        height, options.threads,
        [&](int begin, int end) {
          for (int row = begin; row < end; ++row)
            for (int col = 0; col < width; ++col) {
              if (gbuffer.distance(row, col) == 0.f) continue;
              const Float3 p = gbuffer.position(row, col);
              const auto now = reproject(Eigen::Vector3f(p.x, p.y, p.z));
              if (!now) continue;
              const Float3 q = previous->positions(now->row, now->col);
              if (q == Float3{} || previous->virtual_surface(now->row, now->col) != gbuffer.virtual_surface(row, col))
                continue;
              const auto then = reproject(Eigen::Vector3f(q.x, q.y, q.z));
              if (!then) continue;
              const float eps_pos = (now->screen_and_depth - then->screen_and_depth).cwiseProduct(options.w_p).norm();
              const float eps_n =
                  (1.f - dot(gbuffer.normal(row, col), previous->normals(now->row, now->col))) * options.w_n;
              Float3& rv = images.indirect_real_virtual(row, col);
              Float3& r = images.indirect_real(row, col);
              const Float3 prev_rv = previous->indirect_real_virtual(now->row, now->col);
              const Float3 prev_r = previous->indirect_real(now->row, now->col);
              const float change = std::max(length(rv - prev_rv), length(r - prev_r));
              const float eps_ill = saturate(change * change * change) * options.w_i;
              const float c = saturate(1.f - std::max({eps_pos, eps_n, eps_ill})) * options.c_b;
              const Float3 new_rv = c * prev_rv + (1.f - c) * rv, new_r = c * prev_r + (1.f - c) * r;
              images.real_virtual(row, col) += new_rv - rv;
              images.real(row, col) += new_r - r;
              rv = new_rv;
              r = new_r;
            }
        },
        8);
  }
  return {camera, gbuffer.position, gbuffer.normal, gbuffer.virtual_surface, images.indirect_real_virtual,
          images.indirect_real};
}

}  // namespace relight::render
