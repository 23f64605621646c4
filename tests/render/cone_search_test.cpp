// The point-cone search (cone_search.h): its rules on hand-placed points, and the Vulkan twin
// against the CPU reference on the synthetic scene's surface points.
#include "relight/render/vpl/cone_search.h"
#include "relight/render/dir/ism.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "support/vulkan_test_env.h"
#include "relight/core/error.h"
#include "relight/render/vpl/cone_search_vk.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/virtual_model.h"
#include "relight/render/vpl/vpl.h"
#include "relight/render/scene/sampler.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/synth/trajectory.h"

namespace relight::render {
namespace {

IsmPoint point(Eigen::Vector3f position, Eigen::Vector3f normal, float half_size = 0.001f) {
  return {position, normal.normalized(), half_size, 0};
}

TEST(ConeSearch, TheRayMeetsTheFirstTangentPlaneInsideTheCone) {
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  // A wall at x = 1 facing -x, sampled off the ray's axis, and a nearer point outside the cone.
  const std::vector<IsmPoint> points{
      point({1.f, 0.05f, 0.5f}, -Eigen::Vector3f::UnitX()),   // 2.9 degrees off the axis: in
      point({0.5f, 0.2f, 0.25f}, -Eigen::Vector3f::UnitX()),  // 22 degrees off: out
      point({2.f, 0.f, 1.f}, -Eigen::Vector3f::UnitX()),      // on the axis, but behind the wall
  };
  const Eigen::Vector3f direction = Eigen::Vector3f(1.f, 0.f, 0.5f).normalized();
  const ConeHit hit = cone_search(points, {Eigen::Vector3f::Zero(), up, direction}, ConeShape(5.f));
  ASSERT_EQ(hit.point, 0u);
  // The ray meets the wall's plane x = 1 at t = |(1, 0, 0.5)|, not at the point's own distance.
  EXPECT_NEAR(hit.t, std::sqrt(1.25f), 1e-5f);
  // Nothing nearer than max_t: no hit.
  EXPECT_EQ(cone_search(points, {Eigen::Vector3f::Zero(), up, direction, 1.f}, ConeShape(5.f)).point, ConeHit::kNone);
  // A direction 3 degrees above the tangent plane: the floor point right ahead is below the
  // cone's required elevation.
  const std::vector<IsmPoint> floor{point({1.f, 0.f, 0.f}, up)};
  const float grazing = 3.f * std::numbers::pi_v<float> / 180.f;
  const Eigen::Vector3f flat(std::cos(grazing), 0.f, std::sin(grazing));
  EXPECT_EQ(cone_search(floor, {Eigen::Vector3f::Zero(), up, flat}, ConeShape(5.f)).point, ConeHit::kNone);
  // Near the apex the cone is as wide as the points' spacing: a point 8 mm off a 7 cm hop counts
  // when its splat is 1 cm across (the 5-degree cone is 6 mm wide there).
  const std::vector<IsmPoint> corner{point({0.05f, 0.008f, 0.05f}, -Eigen::Vector3f::UnitX(), 0.005f)};
  const Eigen::Vector3f diagonal = Eigen::Vector3f(1.f, 0.f, 1.f).normalized();
  EXPECT_EQ(cone_search(corner, {Eigen::Vector3f::Zero(), up, diagonal}, ConeShape(5.f)).point, 0u);
}

using ConeSearchVkTest = test::VulkanTest;

TEST_F(ConeSearchVkTest, MatchesTheCpuOnTheSceneSurfacePoints) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = truth::scene_from_synth(synth::default_indoor_scene());
  const IsmPointPools pools = sample_ism_points(scene, {.points_per_vpl = 16384, .pool_factor = 1});
  // Queries from points of the scene, in cosine-distributed directions above their surface.
  std::vector<ConeQuery> queries;
  Pcg32 random(3, 1);
  for (std::size_t i = 0; i < 300; ++i) {
    const IsmPoint& from = pools.real[(i * 53) % pools.real.size()];
    Eigen::Vector3f t, b;
    orthonormal_basis(from.normal, t, b);
    const float phi = 2.f * std::numbers::pi_v<float> * random.uniform(), r = std::sqrt(random.uniform());
    const Eigen::Vector3f direction =
        (r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(1.f - r * r) * from.normal).normalized();
    queries.push_back({from.position, from.normal, direction, i % 5 == 0 ? 1.f : ConeQuery{}.max_t});
  }
  const std::vector<ConeHit> cpu = cone_search_cpu(pools.real, queries, 5.f);
  ConeSearchVk gpu(context);
  gpu.set_points(pools.real);
  const std::vector<ConeHit> vk = gpu.search(queries, 5.f);
  ASSERT_EQ(vk.size(), cpu.size());
  int same = 0, hits = 0;
  for (std::size_t q = 0; q < cpu.size(); ++q) {
    hits += cpu[q].point != ConeHit::kNone ? 1 : 0;
    if (vk[q].point != cpu[q].point) continue;
    ++same;
    if (cpu[q].point != ConeHit::kNone) {
      EXPECT_NEAR(vk[q].t, cpu[q].t, 1e-4f * cpu[q].t) << "query " << q;
    }
  }
  EXPECT_GT(hits, 150);  // not an empty comparison (measured 196 of 300; every fifth query stops at 1 m)
  EXPECT_GE(same, 297) << "the same winner for all but depth ties within rounding";
  EXPECT_THROW((void)gpu.search(queries, 90.f), Error);
}

// Second bounces by the point cone with the search on the GPU equal those with the CPU search
// (the same paths resolved in the same order), on the indoor scene with the pebble.
TEST_F(ConeSearchVkTest, VplsFromTheGpuSearchEqualTheCpuOnes) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = truth::scene_from_synth(synth::default_indoor_scene());
  add_virtual_model(scene, make_glossy_pebble(), Placement::parse("0.35,-0.2,0.75,30"));
  const RayTracer tracer(scene, RayTracer::Build::Fast);
  VplOptions options;
  options.count = 256;
  options.bounces = 2;
  options.bounce_method = BounceMethod::PointCone;
  const std::vector<Vpl> cpu = generate_vpls(scene, tracer, options);
  ConeSearchVk gpu_search(context);
  const std::vector<Vpl> gpu = generate_vpls(scene, tracer, options, {.cone_search = &gpu_search});
  ASSERT_EQ(gpu.size(), cpu.size());
  int second = 0, same = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    if (cpu[i].bounce != 2) continue;
    ++second;
    same += (gpu[i].position - cpu[i].position).norm() < 1e-4f && gpu[i].in_real == cpu[i].in_real &&
                    gpu[i].in_real_virtual == cpu[i].in_real_virtual
                ? 1
                : 0;
  }
  EXPECT_GT(second, 100);
  EXPECT_GE(same, second - second / 50);
}

}  // namespace
}  // namespace relight::render
