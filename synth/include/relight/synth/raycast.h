#pragma once
// A deterministic CPU ray caster for the synthetic scene: analytic intersections, Phong direct
// light with hard shadows (one shadow ray per light) plus the ambient environment term (see the
// shading model in scene.h). Rows are split across std::threads; every pixel depends only on
// its own ray, so the output is identical for any thread count.
#include <Eigen/Core>
#include <array>
#include <limits>
#include <optional>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/synth/scene.h"

namespace relight::synth {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  ///< unit
};

struct Hit {
  double t = 0.0;          ///< distance along the (unit) ray direction, metres
  Eigen::Vector3d point;   ///< world
  Eigen::Vector3d normal;  ///< world, unit, outward from the primitive
  int object = -1;
};

/// Nearest hit with t in (t_min, t_max), or nullopt.
[[nodiscard]] std::optional<Hit> intersect(const Scene& scene, const Ray& ray, double t_min = 1e-9,
                                           double t_max = std::numeric_limits<double>::infinity());
/// Nearest hit of one shape (exposed for tests and the probe); Hit::object is left at -1.
[[nodiscard]] std::optional<Hit> intersect(const Shape& shape, const Ray& ray, double t_min, double t_max);
/// Whether anything blocks the segment from `from` to `to` (both ends excluded).
[[nodiscard]] bool occluded(const Scene& scene, const Eigen::Vector3d& from, const Eigen::Vector3d& to);

/// Material index at a hit, with tag decals applied.
[[nodiscard]] int material_at(const Scene& scene, const Hit& hit);
/// Outgoing linear radiance at `point` towards `to_viewer` (unit), shading model of scene.h.
/// `normal` must face the viewer.
[[nodiscard]] Eigen::Vector3d shade(const Scene& scene, const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                                    const Material& material, const Eigen::Vector3d& to_viewer);

/// Ground truth of one view. Background (nothing hit): depth 0, normal (0,0,0), albedo 0,
/// material 0, radiance = environment.
struct RenderedFrame {
  DepthMap depth;          ///< z along the optical axis, metres (exact)
  NormalMap normals;       ///< camera frame, unit, facing the camera
  RadianceImage albedo;    ///< k_d, linear RGB
  LabelImage material;     ///< material index + 1; 0 = nothing hit
  RadianceImage radiance;  ///< linear RGB radiance reaching the camera
};

/// Renders one pinhole view (one ray through each pixel centre); camera_to_world in the OpenCV
/// camera convention (x right, y down, z forward). threads = 0 uses all hardware threads.
[[nodiscard]] RenderedFrame render_frame(const Scene& scene, const PinholeIntrinsics& intrinsics,
                                         const Pose& camera_to_world, int threads = 0);

/// How the colour camera turns radiance into pixels: value = exposure * gain_c * L_c, clamped
/// to [0, 1], sRGB-encoded (IEC 61966-2-1) and rounded to 8 bits. Gains other than 1 model a
/// white-balance error (for colour-mapping tests).
struct ColorResponse {
  std::array<double, 3> gains{1.0, 1.0, 1.0};
  double exposure = 1.0;
};
[[nodiscard]] double srgb_encode(double linear);
[[nodiscard]] double srgb_decode(double encoded);
[[nodiscard]] ColorImage encode_color(const RadianceImage& radiance, const ColorResponse& response = {});
/// Linear albedo as an 8-bit sRGB image (for gt/albedo PNGs).
[[nodiscard]] ColorImage encode_albedo(const RadianceImage& albedo);

}  // namespace relight::synth
