// Specular fit (specular_fit.h) on the synthetic glossy sphere (k_s 0.6, n 80) with exact normals
// and lights: both solvers recover k_s and n within 10 % and agree with each other; the matte
// wall comes out diffuse. The Vulkan objective (specular_objective_vk.h) equals the CPU one.
#include "relight/brdf/specular_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <cstdio>

#include "brdf_test_scene.h"
#include "support/vulkan_test_env.h"
#include "relight/brdf/specular_objective_vk.h"

namespace relight::brdf {
namespace {

// Every `stride`-th unshadowed pixel of a material, from the exact (HDR, unclipped) radiance.
SpecularProblem material_problem(const char* name, bool from_camera = false) {
  const test::BrdfScene& s = test::brdf_scene();
  const int id = test::material_id(s.scene, name);
  SpecularProblem problem;
  problem.kd = s.scene.materials[static_cast<std::size_t>(id - 1)].kd.cast<float>();
  problem.lights = s.lights;
  if (from_camera) {
    LabelImage ids(s.intrinsics.width, s.intrinsics.height);
    for (std::size_t i = 0; i < ids.size(); ++i) ids.pixels()[i] = s.truth.material.pixels()[i] == id ? 1 : 0;
    problem.samples = select_samples(s.color, s.positions, s.truth.normals, ids, 0, nullptr, 2048);
    return problem;
  }
  std::vector<SpecularSample> all;
  for (int r = 0; r < s.intrinsics.height; ++r) {
    for (int c = 0; c < s.intrinsics.width; ++c) {
      if (s.truth.material(r, c) != id || s.shadowed(r, c)) continue;
      const Float3 l = s.truth.radiance(r, c), p = s.positions(r, c), n = s.truth.normals(r, c);
      all.push_back({{l.x, l.y, l.z}, {p.x, p.y, p.z}, {n.x, n.y, n.z}});
    }
  }
  const std::size_t stride = all.size() / 2048 + 1;
  for (std::size_t i = 0; i < all.size(); i += stride) problem.samples.push_back(all[i]);
  return problem;
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

SpecularFit timed_fit(const SpecularSolver& solver, const SpecularProblem& problem, const SpecularOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const SpecularFit fit = solver.fit(problem, options);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("specular %s: %zu samples, ks %.4f n %.2f rms %.5f evaluations %d, %.1f ms\n", solver.name().c_str(),
              problem.samples.size(), fit.ks, fit.n, fit.rms, fit.evaluations, ms);
  return fit;
}

TEST(SpecularFit, ObjectiveVanishesAtTheTruth) {
  const SpecularProblem problem = material_problem("glossy_blue");
  const double at_truth = specular_objective(problem, {}, 0.6f, 80.f);
  const double off = specular_objective(problem, {}, 0.3f, 20.f);
  EXPECT_LT(at_truth, 1e-6 * off);
}

TEST(SpecularFit, BothSolversRecoverTheGlossySphereAndAgree) {
  const SpecularProblem problem = material_problem("glossy_blue");
  ASSERT_GT(problem.samples.size(), 1000u);
  const SpecularOptions options;
  const SpecularFit nm = timed_fit(*make_nelder_mead_solver(), problem, options);
  const SpecularFit ceres = timed_fit(*make_ceres_solver(), problem, options);
  for (const SpecularFit* fit : {&nm, &ceres}) {
    EXPECT_TRUE(fit->specular);
    EXPECT_LT(rel(fit->ks, 0.6), 0.10);
    EXPECT_LT(rel(fit->n, 80.0), 0.10);
    ASSERT_EQ(fit->light_offsets.size(), 2u);
  }
  EXPECT_LT(rel(nm.ks, ceres.ks), 0.02);
  EXPECT_LT(rel(nm.n, ceres.n), 0.02);
  EXPECT_NEAR(nm.objective, ceres.objective, 1e-3 * std::max(1e-6, ceres.objective) + 1e-8);
}

TEST(SpecularFit, FixedLightsAlsoRecoverTheSphere) {
  const SpecularProblem problem = material_problem("glossy_blue");
  SpecularOptions options;
  options.moving_lights = 0;
  for (const auto& solver : {make_nelder_mead_solver(), make_ceres_solver()}) {
    const SpecularFit fit = timed_fit(*solver, problem, options);
    EXPECT_LT(rel(fit.ks, 0.6), 0.02);
    EXPECT_LT(rel(fit.n, 80.0), 0.02);
    EXPECT_TRUE(fit.light_offsets.empty());
  }
}

TEST(SpecularFit, MovingLightsRecoverAMisplacedLight) {
  // The strongest light 3-4 cm off: with the lights fixed the lobe lands in the wrong place.
  SpecularProblem problem = material_problem("glossy_blue");
  const std::vector<int> strongest = moving_light_indices(problem.lights, 1);
  ASSERT_EQ(strongest.size(), 1u);
  const Eigen::Vector3f error(0.03f, -0.03f, 0.02f);
  problem.lights.lights[static_cast<std::size_t>(strongest[0])].vector += error;
  SpecularOptions fixed;
  fixed.moving_lights = 0;
  const SpecularFit stuck = timed_fit(*make_nelder_mead_solver(), problem, fixed);
  for (const auto& solver : {make_nelder_mead_solver(), make_ceres_solver()}) {
    const SpecularFit fit = timed_fit(*solver, problem, {});
    EXPECT_LT(fit.rms, 0.5 * stuck.rms);
    EXPECT_LT(rel(fit.ks, 0.6), 0.10);
    EXPECT_LT(rel(fit.n, 80.0), 0.10);
    ASSERT_FALSE(fit.light_offsets.empty());
    EXPECT_LT((fit.light_offsets[0] + error).norm(), 0.02f) << fit.light_offsets[0].transpose();
  }
}

TEST(SpecularFit, EightBitCameraSamplesWithClippedPixelsDropped) {
  const SpecularProblem problem = material_problem("glossy_blue", true);
  ASSERT_GT(problem.samples.size(), 1000u);
  for (const auto& solver : {make_nelder_mead_solver(), make_ceres_solver()}) {
    const SpecularFit fit = timed_fit(*solver, problem, {});
    EXPECT_LT(rel(fit.ks, 0.6), 0.10);
    EXPECT_LT(rel(fit.n, 80.0), 0.10);
  }
}

TEST(SpecularFit, MatteWallComesOutDiffuse) {
  const SpecularProblem problem = material_problem("wall");
  for (const auto& solver : {make_nelder_mead_solver(), make_ceres_solver()}) {
    const SpecularFit fit = timed_fit(*solver, problem, {});
    EXPECT_LT(fit.ks, 0.01f);
    EXPECT_LT(fit.rms, 1e-3);
  }
}

class SpecularObjectiveVkTest : public test::VulkanTest {};

TEST_F(SpecularObjectiveVkTest, EqualsTheCpuObjectiveWithFixedAndMovedLights) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const SpecularProblem problem = material_problem("glossy_blue");
  SpecularObjectiveVk gpu(context);
  for (const int moving : {0, 2}) {
    SpecularOptions options;
    options.moving_lights = moving;
    std::vector<SpecularCandidate> candidates = {{0.6f, 80.f}, {0.3f, 20.f}, {0.9f, 5.f}, {0.1f, 500.f}, {0.f, 1.f}};
    SpecularCandidate moved{0.6f, 80.f};
    moved.offsets = {Eigen::Vector3f(0.02f, -0.01f, 0.03f), Eigen::Vector3f(-0.03f, 0.01f, 0.f)};
    candidates.push_back(moved);
    const std::vector<double> f = gpu.evaluate(problem, options, candidates);
    ASSERT_EQ(f.size(), candidates.size());
    const double scale = specular_objective(problem, options, 0.3f, 20.f);
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const SpecularCandidate& c = candidates[i];
      std::vector<Eigen::Vector3f> offsets;
      for (int l = 0; l < moving; ++l) offsets.push_back(c.offsets[static_cast<std::size_t>(l)]);
      const double cpu = specular_objective(problem, options, c.ks, c.n, offsets);
      // float on the GPU, double on the CPU: 1e-3 relative, and near the optimum (F about 1e-6
      // of a poor fit's) the float residuals' rounding.
      EXPECT_NEAR(f[i], cpu, 1e-3 * cpu + 1e-7 * scale) << "moving " << moving << " candidate " << i;
    }
    if (moving == 2) {
      EXPECT_GT(f.back(), 10 * f.front());  // the offsets moved the highlight
    }
  }
}

TEST_F(SpecularObjectiveVkTest, StartGridMinimumIsTheCpuGridMinimum) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const SpecularProblem problem = material_problem("glossy_blue", true);
  SpecularOptions options;
  const std::vector<SpecularCandidate> grid = specular_start_grid(options, 24, 16);
  ASSERT_EQ(grid.size(), 24u * 16u);
  SpecularObjectiveVk gpu(context);
  const std::vector<double> f = gpu.evaluate(problem, options, grid);
  const auto gpu_best = static_cast<std::size_t>(std::min_element(f.begin(), f.end()) - f.begin());
  double cpu_best = std::numeric_limits<double>::infinity();
  for (const SpecularCandidate& c : grid) cpu_best = std::min(cpu_best, specular_objective(problem, options, c.ks, c.n));
  EXPECT_LE(specular_objective(problem, options, grid[gpu_best].ks, grid[gpu_best].n), cpu_best * (1 + 1e-3));
  std::printf("specular objective (Vulkan): grid minimum at k_s %.3f n %.1f\n", grid[gpu_best].ks, grid[gpu_best].n);
  EXPECT_NEAR(grid[gpu_best].n, 80.f, 0.35f * 80.f);  // grid spacing in n: a factor 1.35
}

}  // namespace
}  // namespace relight::brdf
