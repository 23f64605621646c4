// Anti-aliased outlines (dir/edge_coverage.h): the fractional coverage of outline pixels against
// exact sub-pixel visibility, and the composite's outline against the supersampled path tracer's
// (composite.h's separated layer: no halo).
#include "relight/render/dir/edge_coverage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "relight/colormap/color_space.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/dir.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

constexpr int kWidth = 96, kHeight = 72;

/// A white floor and a red virtual cube on it, lit from just above the camera: the cube's shadow
/// falls behind it, so that the outline's error is the outline's, not the shadow map's.
MrScene outline_scene() {
  MrScene scene = test::floor_scene(Eigen::Vector3f::Constant(0.8f), {0.25f, -1.5f, 1.35f}, 6.f);
  test::add_virtual_box(scene, synth::Box{{-0.2, -0.2, 0.0}, {0.2, 0.2, 0.4}},
                        test::diffuse({0.9f, 0.1f, 0.1f}, "red"));
  return scene;
}

MrCamera outline_camera() {
  MrCamera camera = test::camera_at({0.25, -1.5, 1.2}, {0, 0, 0.15}, kWidth, kHeight);
  // Turn the view about its axis so that no edge of the cube is axis-aligned.
  camera.camera_to_world.linear() =
      camera.camera_to_world.linear() * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return camera;
}

Eigen::Vector3f ray_direction(const MrCamera& camera, double u, double v) {
  return (camera.camera_to_world.linear() * camera.intrinsics.ray(u, v).normalized()).cast<float>();
}

/// The real surface at every pixel centre in the camera frame, as the reconstruction gives it.
PositionMap real_positions(const RayTracer& tracer, const MrCamera& camera) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  PositionMap out(kWidth, kHeight, Float3{nan, nan, nan});
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  const Eigen::Isometry3d world_to_camera = camera.camera_to_world.inverse();
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; ++c)
      if (const auto hit = tracer.intersect(Layer::Real, origin, ray_direction(camera, c, r))) {
        const Eigen::Vector3d p = world_to_camera * hit->point.cast<double>();
        out(r, c) = {float(p.x()), float(p.y()), float(p.z())};
      }
  return out;
}

/// The exact fraction of pixel (r, c) in which the virtual cube is in front: 24 x 24 rays.
double true_coverage(const RayTracer& tracer, const MrCamera& camera, int r, int c) {
  constexpr int kRays = 24;
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  int hits = 0;
  for (int i = 0; i < kRays; ++i)
    for (int j = 0; j < kRays; ++j) {
      const Eigen::Vector3f d = ray_direction(camera, c + (j + 0.5) / kRays - 0.5, r + (i + 0.5) / kRays - 0.5);
      const auto real = tracer.intersect(Layer::Real, origin, d);
      if (tracer.occluded(Layer::Virtual, origin, d, real ? real->t : std::numeric_limits<float>::infinity())) ++hits;
    }
  return double(hits) / (kRays * kRays);
}

CoverageImage centre_coverage(const GBuffer& g) {
  CoverageImage out(kWidth, kHeight);
  for (std::size_t i = 0; i < out.size(); ++i)
    out.pixels()[i] = g.distance.pixels()[i] != 0.f && g.virtual_surface.pixels()[i] ? 1.f : 0.f;
  return out;
}

TEST(EdgeCoverage, OutlinePixelsGetTheirSubPixelFraction) {
  const MrScene scene = outline_scene();
  const MrCamera camera = outline_camera();
  const RayTracer tracer(scene);
  const GBuffer gbuffer = gbuffer_cpu(tracer, camera);
  CoverageImage coverage = centre_coverage(gbuffer);
  const CoverageImage before = coverage;
  const RayTracer virtual_tracer(virtual_part(scene), RayTracer::Build::Fast);
  const int outline = refine_edge_coverage(coverage, gbuffer, real_positions(tracer, camera), virtual_tracer, camera);
  const Mask mask = outline_pixels(gbuffer);
  EXPECT_GT(outline, 60);
  double error_sum = 0.0, centre_error_sum = 0.0, worst = 0.0;
  int fractional = 0;
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; ++c) {
      if (!mask(r, c)) {
        EXPECT_EQ(coverage(r, c), before(r, c)) << "only outline pixels change";
        continue;
      }
      const double truth = true_coverage(tracer, camera, r, c);
      error_sum += std::abs(coverage(r, c) - truth);
      centre_error_sum += std::abs(before(r, c) - truth);
      worst = std::max(worst, std::abs(coverage(r, c) - truth));
      fractional += coverage(r, c) > 0.f && coverage(r, c) < 1.f;
    }
  // 16 samples per pixel: the error of a fraction is ~1/16 where an edge crosses a pixel.
  EXPECT_LT(error_sum / outline, 0.05) << "centre samples alone: " << centre_error_sum / outline;
  EXPECT_LT(worst, 0.2);
  EXPECT_GT(fractional, outline / 3);
}

TEST(EdgeCoverage, TheCompositesOutlineMatchesTheSupersampledPathTracerWithoutAHalo) {
  const MrScene scene = outline_scene();
  const MrCamera camera = outline_camera();
  const RayTracer tracer(scene);
  // Direct light only on both sides, so that the band's error is the outline's, not the indirect
  // light's estimate (the path tracer has no shadow map, DIR's is the only other difference).
  PathTracerOptions pt;
  pt.max_bounces = 0;
  pt.roulette_from = 10;
  const DifferentialImages reference = render_reference(scene, camera, 256, pt);
  // The camera sees the real scene as the path tracer renders it.
  const colormap::ToneMap tone_map{};
  ColorImage camera_image(kWidth, kHeight);
  for (std::size_t i = 0; i < camera_image.size(); ++i)
    camera_image.pixels()[i] = colormap::encode_srgb8(colormap::tone_map(reference.real.pixels()[i], tone_map));

  GBuffer gbuffer;
  DifferentialImages dir = render_dir_cpu(scene, camera, {}, {}, &gbuffer);
  const ColorImage aliased =
      differential_composite(camera_image, dir.real_virtual, dir.real, dir.virtual_coverage, tone_map);
  const RayTracer virtual_tracer(virtual_part(scene), RayTracer::Build::Fast);
  (void)refine_edge_coverage(dir.virtual_coverage, gbuffer, real_positions(tracer, camera), virtual_tracer, camera);
  const ColorImage smooth = differential_composite(camera_image, dir.real_virtual, dir.real, dir.virtual_coverage,
                                                   tone_map, {.virtual_centre = &gbuffer.virtual_surface});
  const ColorImage truth = differential_composite(camera_image, reference.real_virtual, reference.real,
                                                  reference.virtual_coverage, tone_map);

  // The band: outline pixels and their neighbours (about 2 px each side of the edge).
  const Mask outline = outline_pixels(gbuffer);
  const auto in_band = [&](int r, int c) {
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        if (outline.in_bounds(r + i, c + j) && outline(r + i, c + j)) return true;
    return false;
  };
  double aliased_sq = 0.0, smooth_sq = 0.0;
  int n = 0, outside = 0;
  for (int r = 2; r < kHeight - 2; ++r)
    for (int c = 2; c < kWidth - 2; ++c) {
      if (!in_band(r, c)) continue;
      const Rgb8 a = aliased(r, c), s = smooth(r, c), t = truth(r, c);
      for (const auto& [x, y, z] : {std::tuple{a.r, s.r, t.r}, {a.g, s.g, t.g}, {a.b, s.b, t.b}}) {
        aliased_sq += (double(x) - z) * (double(x) - z);
        smooth_sq += (double(y) - z) * (double(y) - z);
      }
      ++n;
      // No halo: a blend lies between the fully virtual and the fully real pixels around it.
      int lo[3] = {255, 255, 255}, hi[3] = {0, 0, 0};
      for (int i = -2; i <= 2; ++i)
        for (int j = -2; j <= 2; ++j) {
          const float cov = dir.virtual_coverage(r + i, c + j);
          if (cov != 0.f && cov != 1.f) continue;
          const Rgb8 p = smooth(r + i, c + j);
          const int v[3] = {p.r, p.g, p.b};
          for (int ch = 0; ch < 3; ++ch) lo[ch] = std::min(lo[ch], v[ch]), hi[ch] = std::max(hi[ch], v[ch]);
        }
      const int v[3] = {s.r, s.g, s.b};
      for (int ch = 0; ch < 3; ++ch) {
        const bool out_of_range = v[ch] < lo[ch] - 3 || v[ch] > hi[ch] + 3;
        outside += out_of_range;
        if (out_of_range)
          std::cout << "(" << r << ", " << c << ") channel " << ch << ": " << v[ch] << " outside [" << lo[ch] << ", "
                    << hi[ch] << "], coverage " << dir.virtual_coverage(r, c) << " truth "
                    << int(ch == 0   ? t.r
                           : ch == 1 ? t.g
                                     : t.b)
                    << " aliased "
                    << int(ch == 0   ? a.r
                           : ch == 1 ? a.g
                                     : a.b)
                    << "\n";
      }
    }
  ASSERT_GT(n, 100);
  const double aliased_rmse = std::sqrt(aliased_sq / (3.0 * n)), smooth_rmse = std::sqrt(smooth_sq / (3.0 * n));
  EXPECT_LT(smooth_rmse, 0.5 * aliased_rmse) << "band of " << n << " px: aliased " << aliased_rmse;
  std::cout << "outline band (" << n << " px) RMSE against the path tracer: aliased " << aliased_rmse
            << ", anti-aliased " << smooth_rmse << " (8-bit levels)\n";
  EXPECT_EQ(outside, 0) << "pixels of the band outside the range of their neighbours (a halo)";
}

}  // namespace
}  // namespace relight::render
