// Mirrors, metals and glass (specular_material.h, specular_bsdf.h) in the differential path
// tracer, against closed-form answers: Fresnel's and Snell's laws, a mirror showing a lit wall,
// a glass slab seen through and casting its transmitted light, a lamp focused by a mirror and the
// sun focused by a glass ball.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/core/error.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/specular_bsdf.h"
#include "relight/render/scene/tessellation.h"
#include "specular_scenes.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using Eigen::Vector3f;
using test::at;
using test::camera_at;
using test::emitter;
using test::pixel_hit;
using test::slab_transmittance;
using test::specular_material;
using test::with_layer;
constexpr float kPi = std::numbers::pi_v<float>;

TEST(SpecularBsdf, DielectricFresnelHasItsKnownValues) {
  EXPECT_NEAR(dielectric_fresnel(1.f, 1.f, 1.5f), 0.04f, 1e-6f);  // ((n - 1) / (n + 1))^2
  EXPECT_NEAR(dielectric_fresnel(1.f, 1.5f, 1.f), 0.04f, 1e-6f);
  // Brewster's angle: the parallel polarisation is not reflected, F = r_s^2 / 2.
  const float brewster = std::atan(1.5f);
  const float cos_t = std::cos(kPi / 2.f - brewster);
  const float rs = (std::cos(brewster) - 1.5f * cos_t) / (std::cos(brewster) + 1.5f * cos_t);
  EXPECT_NEAR(dielectric_fresnel(std::cos(brewster), 1.f, 1.5f), 0.5f * rs * rs, 1e-6f);
  // Reciprocity across the interface, total internal reflection past the critical angle, and a
  // mirror at grazing incidence.
  for (float degrees : {10.f, 30.f, 41.f}) {
    const float sin_inside = std::sin(degrees * kPi / 180.f), sin_outside = 1.5f * sin_inside;
    EXPECT_NEAR(dielectric_fresnel(std::sqrt(1.f - sin_inside * sin_inside), 1.5f, 1.f),
                dielectric_fresnel(std::sqrt(1.f - sin_outside * sin_outside), 1.f, 1.5f), 1e-5f);
  }
  EXPECT_EQ(dielectric_fresnel(std::cos(42.f * kPi / 180.f), 1.5f, 1.f), 1.f);  // critical angle 41.8 degrees
  EXPECT_NEAR(dielectric_fresnel(0.f, 1.f, 1.5f), 1.f, 1e-6f);
  EXPECT_EQ(schlick_fresnel(Vector3f(0.9f, 0.6f, 0.3f), 1.f), Vector3f(0.9f, 0.6f, 0.3f));
  EXPECT_EQ(schlick_fresnel(Vector3f(0.9f, 0.6f, 0.3f), 0.f), Vector3f::Ones());
}

TEST(SpecularBsdf, RefractionFollowsSnellAndTheFresnelChoiceConservesFlux) {
  const Vector3f outward = Vector3f::UnitZ();
  const Vector3f wo = Vector3f(std::sin(0.6f), 0.f, std::cos(0.6f));  // from outside, 34 degrees
  const SpecularMaterial glass = dielectric(1.5f);
  const float f = dielectric_fresnel(wo.z(), 1.f, 1.5f);
  int reflected = 0;
  Vector3f flux = Vector3f::Zero();
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const auto s = sample_specular(glass, outward, wo, (i + 0.5f) / n, Transport::Importance);
    ASSERT_TRUE(s);
    flux += s->weight;
    if (!s->transmitted) {
      ++reflected;
      EXPECT_NEAR(s->wi.x(), -wo.x(), 1e-6f);
      EXPECT_NEAR(s->wi.z(), wo.z(), 1e-6f);
    } else {
      EXPECT_NEAR(-s->wi.x() * 1.5f, wo.x(), 1e-5f);  // sin_t n = sin_i, on the far side
      EXPECT_LT(s->wi.z(), 0.f);
    }
  }
  EXPECT_NEAR(reflected / double(n), f, 1e-3);
  EXPECT_NEAR(flux.x() / n, 1.f, 1e-6f);  // importance: every sample carries the flux on
  // Radiance entering the denser medium is compressed by n^2; from inside it is total internal
  // reflection beyond 41.8 degrees.
  const auto in = sample_specular(glass, outward, wo, 0.999f, Transport::Radiance);
  ASSERT_TRUE(in && in->transmitted);
  EXPECT_NEAR(in->weight.x(), 1.f / 2.25f, 1e-6f);
  const Vector3f inside_steep(std::sin(0.8f), 0.f, -std::cos(0.8f));  // 46 degrees, inside
  const auto tir = sample_specular(glass, outward, inside_steep, 0.999f, Transport::Radiance);
  ASSERT_TRUE(tir);
  EXPECT_FALSE(tir->transmitted);
  EXPECT_TRUE(
      beer_lambert(dielectric(1.5f, {0.5f, 0.8f, 1.f}, 0.1f), 0.2f).isApprox(Vector3f(0.25f, 0.64f, 1.f), 1e-5f));
  EXPECT_EQ(beer_lambert(glass, 5.f), Vector3f::Ones());
}

TEST(SpecularScene, OutOfRangeSpecularMaterialsAreRefused) {
  MrScene scene;
  scene.add_material(specular_material(dielectric(0.8f), "thin air"));
  EXPECT_THROW(scene.validate(), Error);
  scene.materials[0] = specular_material(dielectric(1.5f, {0.f, 1.f, 1.f}, 0.1f), "black glass");
  EXPECT_THROW(scene.validate(), Error);
  scene.materials[0] = specular_material(conductor({1.2f, 1.f, 1.f}), "brighter than light");
  EXPECT_THROW(scene.validate(), Error);
  scene.materials[0] = specular_material(dielectric(1.5f, {0.5f, 1.f, 1.f}, 0.1f), "green glass");
  EXPECT_NO_THROW(scene.validate());
}

TEST(SpecularPathTracer, AMirrorShowsTheWallItFacesWithSchlicksColouredFresnel) {
  MrScene scene;
  scene.meshes.push_back(
      with_layer(tessellate_rectangle({-1, 0, 0}, {1, 0, 0}, {0, 3, 0}, {0, 0, 3}, scene.add_material(emitter(1.f))),
                 "wall", true));
  const SpecularMaterial metal = conductor({0.9f, 0.6f, 0.3f});
  scene.meshes.push_back(with_layer(tessellate_rectangle({0.5f, 0, 0}, {-1, 0, 0}, {0, 0.5f, 0}, {0, 0, 0.5f},
                                                         scene.add_material(specular_material(metal, "mirror"))),
                                    "mirror", false));
  const MrCamera camera = camera_at({-0.3, -0.6, 0.05}, {0.5, 0, 0}, 48, 36);
  const DifferentialImages images = render_reference(scene, camera, 4);
  const RayTracer tracer(scene);
  int checked = 0;
  for (int row = 0; row < 36; ++row)
    for (int col = 0; col < 48; ++col) {
      const auto hit = pixel_hit(tracer, camera, row, col, Layer::Virtual);
      if (!hit || std::abs(hit->point.y()) > 0.45f || std::abs(hit->point.z()) > 0.45f) continue;
      const Eigen::Vector3d d = camera.camera_to_world.linear() * camera.intrinsics.ray(col, row).normalized();
      const Vector3f expected = schlick_fresnel(metal.reflectance, static_cast<float>(std::abs(d.x())));
      const Vector3f got = at(images.real_virtual, row, col);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 0.01f * expected[c]) << row << "," << col;
      EXPECT_EQ(images.virtual_coverage(row, col), 1.f);
      EXPECT_EQ(at(images.real, row, col), Vector3f::Zero());  // L_r sees past the virtual mirror into the dark
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(SpecularPathTracer, AGlassSlabSeenThroughDimsByFresnelAndBeerLambert) {
  MrScene scene;
  scene.meshes.push_back(
      with_layer(tessellate_rectangle({0, 1, 0}, {0, -1, 0}, {2, 0, 0}, {0, 0, 2}, scene.add_material(emitter(1.f))),
                 "wall", true));
  const Vector3f colour(0.5f, 0.8f, 1.f);
  scene.meshes.push_back(
      with_layer(tessellate_box({-0.3f, 0.2f, -0.3f}, {0.3f, 0.3f, 0.3f},
                                scene.add_material(specular_material(dielectric(1.5f, colour, 0.1f), "glass"))),
                 "slab", true));
  MrCamera camera;
  camera.intrinsics = {525.0, 525.0, 15.5, 11.5, 32, 24};  // +-1.7 degrees: normal incidence
  camera.camera_to_world = synth::look_at({0, -1, 0}, {0, 1, 0});
  const DifferentialImages images = render_reference(scene, camera, 64);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int row = 0; row < 24; ++row)
    for (int col = 0; col < 32; ++col) {
      sum += at(images.real_virtual, row, col).cast<double>();
      ASSERT_EQ(images.real_virtual(row, col), images.real(row, col));  // all real: no difference
    }
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(sum[c] / (24 * 32), slab_transmittance(1.5f, colour[c]), 0.01 * slab_transmittance(1.5f, colour[c]))
        << "channel " << c;
}

TEST(SpecularPathTracer, AGlassSlabCastsTheSunsLightThroughItWithFresnelAndAbsorption) {
  const float sun = 3.f, albedo = 0.5f;
  const Vector3f colour(0.5f, 0.8f, 1.f);
  const MrScene scene = test::sunlit_glass_slab(sun, albedo, colour);
  const MrCamera camera = camera_at({0, -1.6, 0.35}, {0, 0, 0}, 64, 48);
  PathTracerOptions options;
  options.max_bounces = 0;
  options.caustic_paths_per_pixel = 4.0;
  const DifferentialImages images = render_reference(scene, camera, 32, options);
  const auto under = test::floor_pixels(scene, camera, {-0.3f, -0.3f}, {0.3f, 0.3f});
  const auto beside = test::floor_pixels(scene, camera, {0.7f, -0.5f}, {1.5f, 0.5f});
  ASSERT_GT(under.size(), 60u);
  ASSERT_GT(beside.size(), 30u);
  const double lit = albedo / std::numbers::pi * sun;
  test::expect_sun_through_slab(images, under, lit, colour, 0.03, 1e-4);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_over(images.real_virtual, beside)[c], lit, 1e-4 * lit);
  for (const auto& [row, col] : under)
    EXPECT_NEAR(images.real_virtual(row, col).z, lit * slab_transmittance(1.5f, 1.f), 0.25 * lit) << row << "," << col;
}

TEST(SpecularPathTracer, AMirrorAboveALampDoublesItOnTheFloor) {
  // A lamp under a ceiling mirror lights the floor directly and as its mirror image (at twice
  // the mirror's height minus its own), with the mirror's Fresnel at that angle.
  const float albedo = 0.5f, intensity = 2.f, lamp = 1.f, mirror = 1.2f;
  MrScene scene = test::floor_scene(Vector3f::Constant(albedo), {0, 0, lamp}, intensity);
  const SpecularMaterial metal = conductor(Vector3f::Constant(0.8f));
  scene.meshes.push_back(with_layer(tessellate_rectangle({0, 0, mirror}, {0, 0, -1}, {2.5f, 0, 0}, {0, 2.5f, 0},
                                                         scene.add_material(specular_material(metal, "mirror"))),
                                    "mirror", false));
  const MrCamera camera = camera_at({0, -1.4, 0.7}, {0, 0, 0}, 32, 24);
  PathTracerOptions options;
  options.max_bounces = 0;
  options.caustic_paths_per_pixel = 16.0;
  const DifferentialImages images = render_reference(scene, camera, 64, options);
  const RayTracer tracer(scene);
  const Vector3f image_lamp(0, 0, 2 * mirror - lamp);
  double sum_ratio = 0.0;
  int checked = 0;
  for (int row = 0; row < 24; ++row)
    for (int col = 0; col < 32; ++col) {
      const auto hit = pixel_hit(tracer, camera, row, col, Layer::Real);
      if (!hit || std::abs(hit->point.x()) > 0.8f || std::abs(hit->point.y()) > 0.8f) continue;
      const Vector3f q = hit->point;
      const float d = (Vector3f(0, 0, lamp) - q).norm(), d_image = (image_lamp - q).norm();
      const float direct = intensity * (lamp / d) / (d * d);
      const float cos_image = image_lamp.z() / d_image;
      const float mirrored =
          schlick_fresnel(metal.reflectance, cos_image).x() * intensity * cos_image / (d_image * d_image);
      const float expected_rv = albedo / kPi * (direct + mirrored), expected_r = albedo / kPi * direct;
      // The pixel's footprint (jittered samples) against its centre's value: a few percent far off;
      // the mirror's share, which L_r must not see, is 30 to 60 percent.
      EXPECT_NEAR(images.real(row, col).y, expected_r, 0.04f * expected_r) << row << "," << col;
      EXPECT_NEAR(images.real_virtual(row, col).y, expected_rv, 0.35f * expected_rv) << row << "," << col;
      sum_ratio += images.real_virtual(row, col).y / expected_rv;
      ++checked;
    }
  ASSERT_GT(checked, 200);
  EXPECT_NEAR(sum_ratio / checked, 1.0, 0.03);
}

TEST(SpecularPathTracer, AGlassBallFocusesTheSunBelowIt) {
  const float albedo = 0.5f;
  MrScene scene = test::floor_scene(Vector3f::Constant(albedo), {0, 0, 1}, 0.f);
  scene.lights[0].kind = LightKind::Directional;
  scene.lights[0].direction = Vector3f::UnitZ();
  scene.lights[0].intensity = Vector3f::Ones();
  // A ball lens of radius R focuses paraxial light at n R / (2 (n - 1)) from its centre.
  const float radius = 0.1f, ior = 1.5f, focus = ior * radius / (2.f * (ior - 1.f));
  scene.meshes.push_back(with_layer(
      tessellate_sphere({0, 0, focus}, radius, scene.add_material(specular_material(dielectric(ior), "glass"))), "ball",
      true));
  const MrCamera camera = camera_at({0, -0.5, 0.35}, {0, 0, 0}, 96, 72);
  PathTracerOptions options;
  options.max_bounces = 0;
  options.caustic_paths_per_pixel = 2.0;
  const DifferentialImages images = render_reference(scene, camera, 16, options);
  const RayTracer tracer(scene);
  const double lit = albedo / std::numbers::pi;
  float peak = 0.f;
  Vector3f peak_point = Vector3f::Zero();
  int far_checked = 0;
  double far_sum = 0.0;
  for (int row = 0; row < 72; ++row)
    for (int col = 0; col < 96; ++col) {
      const auto hit = pixel_hit(tracer, camera, row, col, Layer::Real);
      if (!hit || std::abs(hit->point.z()) > 1e-4f) continue;  // the ball itself
      const float r = hit->point.head<2>().norm();
      if (images.real(row, col).y > peak) {
        peak = images.real(row, col).y;
        peak_point = hit->point;
      }
      if (r > 0.3f) {
        far_sum += images.real(row, col).y;
        ++far_checked;
      }
    }
  EXPECT_LT(peak_point.head<2>().norm(), 0.025f) << peak_point.transpose();
  EXPECT_GT(peak, 5.0 * lit);
  ASSERT_GT(far_checked, 100);
  EXPECT_NEAR(far_sum / far_checked, lit, 0.02 * lit);  // away from the ball: the sun alone
}

TEST(SpecularPathTracer, ASceneWithoutSpecularMaterialsTracesNoLightPaths) {
  const MrScene scene = test::floor_scene(Vector3f::Constant(0.6f), {0.2f, 0.1f, 1.5f}, 2.f);
  const MrCamera camera = camera_at({0, -1.2, 1.4}, {0, 0, 0}, 32, 24);
  PathTracerOptions without;
  without.caustic_paths_per_pixel = 0.0;
  DifferentialPathTracer a(scene), b(scene, without);
  a.reset(camera);
  b.reset(camera);
  a.add_samples(2);
  b.add_samples(2);
  EXPECT_EQ(a.rays_traced(), b.rays_traced());
  for (int row = 0; row < 24; ++row)
    for (int col = 0; col < 32; ++col) ASSERT_EQ(a.images().real_virtual(row, col), b.images().real_virtual(row, col));
  PathTracerOptions negative;
  negative.caustic_paths_per_pixel = -1.0;
  EXPECT_THROW(DifferentialPathTracer(scene, negative), Error);
}

}  // namespace
}  // namespace relight::render
