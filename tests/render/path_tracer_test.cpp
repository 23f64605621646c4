#include "relight/render/reference/path_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/core/error.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using test::camera_at;
using test::floor_scene;

Eigen::Vector3f at(const RadianceImage& image, int row, int col) {
  const Float3 p = image(row, col);
  return {p.x, p.y, p.z};
}

/// World point of a pixel centre on the real geometry (nullopt on sky).
std::optional<Eigen::Vector3f> floor_point(const MrScene& scene, const MrCamera& camera, int row, int col) {
  const RayTracer tracer(scene);
  const Eigen::Vector3d d = camera.camera_to_world.linear() * camera.intrinsics.ray(col, row).normalized();
  const auto hit = tracer.intersect(Layer::Real, camera.camera_to_world.translation().cast<float>(), d.cast<float>());
  if (!hit) return std::nullopt;
  return hit->point;
}

TEST(DifferentialPathTracer, WithoutVirtualObjectsTheDifferenceIsExactlyZeroAndDirectLightIsAnalytic) {
  const Eigen::Vector3f light(0.2f, 0.1f, 1.5f);
  const MrScene scene = floor_scene(Eigen::Vector3f::Constant(0.6f), light, 2.f);
  const MrCamera camera = camera_at({0, -1.2, 1.4}, {0, 0, 0}, 96, 72);
  PathTracerOptions options;
  options.max_bounces = 4;
  const DifferentialImages images = render_reference(scene, camera, 8, options);
  int checked = 0;
  for (int row = 0; row < 72; row += 3)
    for (int col = 0; col < 96; col += 3) {
      ASSERT_EQ(images.real_virtual(row, col), images.real(row, col));
      EXPECT_EQ(images.virtual_coverage(row, col), 0.f);
      const auto p = floor_point(scene, camera, row, col);
      if (!p || std::abs(p->x()) > 1.5f || std::abs(p->y()) > 1.5f) continue;  // footprint off the floor
      // L = k_d / pi * I cos(theta) / d^2 (a plane cannot light itself; the sky is black).
      const Eigen::Vector3f to_light = light - *p;
      const float d = to_light.norm();
      const float expected = 0.6f / std::numbers::pi_v<float> * 2.f * (to_light.z() / d) / (d * d);
      EXPECT_NEAR(images.real(row, col).y, expected, 0.015f * expected) << row << "," << col;
      ++checked;
    }
  EXPECT_GT(checked, 300);
}

MrScene furnace(float albedo, float emission) {
  MrScene scene;
  PhongMaterial wall = test::diffuse(Eigen::Vector3f::Constant(albedo), "furnace");
  wall.emission = Eigen::Vector3f::Constant(emission);
  TriangleMesh sphere = truth::tessellate(synth::Sphere{{0, 0, 0}, 1.0}, scene.add_material(wall), {48});
  sphere.normals.clear();  // flat facets: no sample is lost to a shading/geometric normal mismatch
  scene.meshes.push_back(sphere);
  return scene;
}

TEST(DifferentialPathTracer, WhiteFurnaceConvergesToEmissionOverOneMinusAlbedo) {
  const MrScene scene = furnace(0.5f, 1.f);
  PathTracerOptions options;
  options.max_bounces = 100000;
  const DifferentialImages images = render_reference(scene, camera_at({0, 0, 0}, {1, 0, 0}, 16, 12), 64, options);
  double sum = 0.0;
  for (int row = 0; row < 12; ++row)
    for (int col = 0; col < 16; ++col) sum += images.real_virtual(row, col).x;
  EXPECT_NEAR(sum / (16 * 12), 2.0, 0.02);  // 1 / (1 - 0.5) within 1 %
}

TEST(DifferentialPathTracer, BounceLimitTruncatesTheNeumannSeries) {
  // Cosine sampling of a Lambertian surface has weight k_d exactly, so without roulette every
  // sample is L_e (1 + rho + rho^2).
  const MrScene scene = furnace(0.5f, 1.f);
  PathTracerOptions options;
  options.max_bounces = 2;
  options.roulette_from = 1000;
  const DifferentialImages images = render_reference(scene, camera_at({0, 0, 0}, {0, 1, 0}, 8, 6), 4, options);
  for (int row = 0; row < 6; ++row)
    for (int col = 0; col < 8; ++col) EXPECT_NEAR(images.real(row, col).x, 1.75f, 1e-5f);
}

struct OccluderSetup {
  MrScene without, with;
  MrCamera camera = camera_at({0, -2.2, 2.4}, {0, 0, 0}, 64, 48);
  Eigen::Vector3f light{0, 0, 2};
  float intensity = 4.f;
  float albedo = 0.5f;
  float sky = 0.2f;
};

OccluderSetup occluder_setup() {
  OccluderSetup s;
  s.without = floor_scene(Eigen::Vector3f::Constant(s.albedo), s.light, s.intensity);
  s.without.environment.radiance = Eigen::Vector3f::Constant(s.sky);
  s.with = s.without;
  test::add_virtual_box(s.with, synth::Box{{-0.2, -0.2, 0.8}, {0.2, 0.2, 1.0}},
                        test::diffuse(Eigen::Vector3f::Constant(0.5f), "occluder"));
  return s;
}

TEST(DifferentialPathTracer, VirtualOccluderDarkensOnlyLrvAndLeavesLrUnchanged) {
  const OccluderSetup s = occluder_setup();
  PathTracerOptions options;
  options.max_bounces = 2;
  const DifferentialImages without = render_reference(s.without, s.camera, 16, options);
  const DifferentialImages with = render_reference(s.with, s.camera, 16, options);
  int umbra = 0, lit = 0;
  double lit_rv = 0.0, lit_r = 0.0;
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      // L_r never sees the virtual box: it is the same image, bit for bit.
      ASSERT_EQ(with.real(row, col), without.real(row, col)) << row << "," << col;
      if (with.virtual_coverage(row, col) > 0.f) continue;
      const auto p = floor_point(s.with, s.camera, row, col);
      if (!p) continue;
      const Eigen::Vector3f to_light = s.light - *p;
      const float d = to_light.norm();
      const float direct = s.albedo / std::numbers::pi_v<float> * s.intensity * (to_light.z() / d) / (d * d);
      const float lrv = with.real_virtual(row, col).x, lr = with.real(row, col).x;
      if (std::abs(p->x()) < 0.3f && std::abs(p->y()) < 0.3f) {  // the box's umbra (shadow to |x| = 0.33)
        ++umbra;
        EXPECT_NEAR(lr - lrv, direct, 0.1f * direct + 0.02f) << "direct light removed in the shadow";
        EXPECT_GT(lrv, 0.3f * s.albedo * s.sky) << "the sky still lights the shadow";
      } else if (p->head<2>().norm() > 1.2f) {
        ++lit;
        lit_rv += lrv;
        lit_r += lr;
      }
    }
  EXPECT_GT(umbra, 20);
  EXPECT_GT(lit, 200);
  // Far from the box it only hides a little sky (about 0.07 sr of it).
  EXPECT_LT(lit_rv, lit_r);
  EXPECT_NEAR(lit_rv / lit_r, 1.0, 0.03);
}

TEST(DifferentialPathTracer, RedVirtualWallBleedsRedOntoTheWhiteFloorOnlyInLrv) {
  MrScene scene = floor_scene(Eigen::Vector3f::Constant(0.8f), {-0.5f, 0.f, 1.5f}, 3.f);
  test::add_virtual_box(scene, synth::Box{{0.5, -0.6, 0.0}, {0.55, 0.6, 0.7}},
                        test::diffuse({0.9f, 0.05f, 0.05f}, "red wall"));
  const MrCamera camera = camera_at({-1.2, -1.2, 1.3}, {0.3, 0, 0}, 64, 48);
  PathTracerOptions options;
  options.max_bounces = 2;
  const DifferentialImages images = render_reference(scene, camera, 32, options);
  Eigen::Vector3d delta = Eigen::Vector3d::Zero(), real = Eigen::Vector3d::Zero();
  int pixels = 0;
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      if (images.virtual_coverage(row, col) > 0.f) continue;
      const auto p = floor_point(scene, camera, row, col);
      if (!p || p->x() < 0.15f || p->x() > 0.45f || std::abs(p->y()) > 0.3f) continue;
      const Eigen::Vector3f lr = at(images.real, row, col);
      EXPECT_EQ(lr.x(), lr.y()) << "a white floor under a white light stays grey in L_r";
      EXPECT_EQ(lr.y(), lr.z());
      delta += (at(images.real_virtual, row, col) - lr).cast<double>();
      real += lr.cast<double>();
      ++pixels;
    }
  ASSERT_GT(pixels, 30);
  EXPECT_GT(delta.x(), 0.01 * real.x()) << "red added near the wall";
  EXPECT_GT(delta.x(), 10.0 * std::abs(delta.y()));
  EXPECT_GT(delta.x(), 10.0 * std::abs(delta.z()));
}

TEST(DifferentialPathTracer, ResultDoesNotDependOnThreadsOrPassSizes) {
  const OccluderSetup s = occluder_setup();
  PathTracerOptions one_thread;
  one_thread.threads = 1;
  PathTracerOptions two_threads;
  two_threads.threads = 2;
  DifferentialPathTracer progressive(s.with, two_threads);
  progressive.reset(s.camera);
  progressive.add_samples(1);
  progressive.add_samples(3);
  const DifferentialImages a = render_reference(s.with, s.camera, 4, one_thread);
  const DifferentialImages b = progressive.images();
  EXPECT_EQ(b.samples_per_pixel, 4);
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      ASSERT_EQ(a.real_virtual(row, col), b.real_virtual(row, col));
      ASSERT_EQ(a.real(row, col), b.real(row, col));
    }
  EXPECT_GT(progressive.rays_traced(), 4u * 48u * 64u);
}

double rmse(const RadianceImage& a, const RadianceImage& b) {
  double sum = 0.0;
  for (int row = 0; row < a.height(); ++row)
    for (int col = 0; col < a.width(); ++col) {
      const Float3 d = a(row, col) - b(row, col);
      sum += dot(d, d);
    }
  return std::sqrt(sum / (3.0 * a.width() * a.height()));
}

TEST(DifferentialPathTracer, ErrorFallsAsOneOverRootSamples) {
  OccluderSetup s = occluder_setup();
  s.camera = camera_at({0, -2.2, 2.4}, {0, 0, 0}, 16, 12);
  PathTracerOptions reference_options;
  reference_options.seed = 99;
  const RadianceImage reference = render_reference(s.with, s.camera, 2048, reference_options).real_virtual;
  const double coarse = rmse(render_reference(s.with, s.camera, 8).real_virtual, reference);
  const double fine = rmse(render_reference(s.with, s.camera, 128).real_virtual, reference);
  const double slope = std::log(fine / coarse) / std::log(128.0 / 8.0);
  EXPECT_NEAR(slope, -0.5, 0.1);
}

TEST(DifferentialPathTracer, RejectsBadOptions) {
  const OccluderSetup s = occluder_setup();
  PathTracerOptions options;
  options.max_bounces = -1;
  EXPECT_THROW(DifferentialPathTracer(s.with, options), Error);
  DifferentialPathTracer tracer(s.with);
  EXPECT_THROW(tracer.add_samples(1), LogicError);
}

}  // namespace
}  // namespace relight::render
