// brdf/*: BRDF estimation on one 640x480 view of the synthetic scene (exact positions, normals
// and lights, 8-bit camera image).
//   kmeans/cpu, kmeans/vulkan: K = 6, 5 attempts x at most 20 iterations (eps 1e-4), k-means++
//     seeds, on the frame's k_d (307200 points), against cv::kmeans with the same settings
//     (KMEANS_PP_CENTERS); compactness_rel = ours / OpenCV's (goal <= 1.01), ratio goal >= 20.
//   specular/nelder_mead, specular/ceres: ms to fit every cluster of the frame (<= 2048 samples
//     each, two moving lights); ks_rel_error and n_rel_error on the glossy sphere (k_s 0.6, n 80)
//     fitted from the camera image with its true k_d. Goal <= 15 ms.
//   specular/objective_vulkan: F of the glossy sphere's 2048 samples at the 24 x 16 (n, k_s) start
//     grid of the Vulkan backend, on the GPU against the CPU objective (double) per candidate.
//   brdf/frame: the whole estimation per frame (highlights, k_d, warm-started K-means, Nelder-Mead
//     fit), steady state. Goal <= 25 ms.
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "bench.h"
#include "vulkan_timing.h"
#include "relight/brdf/brdf_stages.h"
#include "relight/brdf/kmeans_vk.h"
#include "relight/brdf/specular_objective_vk.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"
#include "relight/vk/context.h"

namespace {

using namespace relight;
using namespace relight::brdf;

struct Frame {
  synth::Scene scene;
  synth::RenderedFrame truth;
  ColorImage color;
  PositionMap positions;
  ShadingLights lights;
  BrdfFrame estimate;  // highlights, k_d and a first clustering
  std::vector<Float3> points;
};

BrdfOptions options_for(const Frame& f) {
  BrdfOptions options;
  options.ambient = f.scene.environment.cast<float>();
  return options;
}

const Frame& frame() {
  static const Frame f = [] {
    Frame f;
    f.scene = synth::default_indoor_scene();
    const PinholeIntrinsics intrinsics = PinholeIntrinsics::kinect_v1();
    const Pose pose = synth::make_trajectory(synth::Trajectory::Static, 1, 0, f.scene)[0];
    f.truth = synth::render_frame(f.scene, intrinsics, pose);
    f.color = synth::encode_color(f.truth.radiance);
    f.positions = PositionMap(intrinsics.width, intrinsics.height);
    for (int r = 0; r < intrinsics.height; ++r) {
      for (int c = 0; c < intrinsics.width; ++c) {
        const float z = f.truth.depth(r, c);
        if (z <= 0.f) continue;
        const Eigen::Vector3d p = intrinsics.unproject(c, r, z);
        f.positions(r, c) = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      }
    }
    lights::LightSet set;
    for (const synth::PointLight& l : f.scene.lights) {
      lights::Light light;
      light.kind = lights::LightKind::Point;
      light.position = l.position;
      light.power = l.colour * l.intensity;
      set.lights.push_back(light);
    }
    f.lights = to_camera_frame(set, pose, f.scene.environment.cast<float>());
    KMeansCpu engine;
    KMeansTracker tracker;
    estimate_brdf(f.color, f.positions, f.truth.normals, f.lights, options_for(f), engine, tracker,
                  *make_nelder_mead_solver(), f.estimate);
    std::vector<std::uint32_t> pixels;
    gather_points(f.estimate.kd, f.estimate.kd_valid, f.points, pixels);
    return f;
  }();
  return f;
}

constexpr int kClusters = 6, kAttempts = 5, kIterations = 20;
constexpr double kEpsilon = 1e-4;

double cv_kmeans(const std::vector<Float3>& points, cv::Mat& labels, cv::Mat& centres) {
  const cv::Mat data(static_cast<int>(points.size()), 3, CV_32F, const_cast<Float3*>(points.data()));
  return cv::kmeans(data, kClusters, labels, cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                                              kIterations, kEpsilon),
                    kAttempts, cv::KMEANS_PP_CENTERS, centres);
}

bench::Json kmeans_case(const bench::Options& options, KMeansEngine& engine, const std::string& device) {
  const Frame& f = frame();
  KMeansOptions ko;
  ko.clusters = kClusters;
  ko.max_iterations = kIterations;
  ko.epsilon = kEpsilon;
  std::mt19937_64 rng(1);
  KMeansResult ours;
  double theirs = 0.0;
  cv::Mat labels, centres;
  const int repetitions = std::min(options.repetitions, 3);  // cv::kmeans takes about a second
  const bench::Comparison cmp = bench::compare_interleaved([&] { ours = kmeans(engine, f.points, ko, kAttempts, rng); },
                                                           [&] { theirs = cv_kmeans(f.points, labels, centres); },
                                                           repetitions);
  bench::Json json = bench::comparison_json(cmp, "cv_kmeans");
  json["compactness"] = ours.compactness;
  json["baseline_compactness"] = theirs;
  json["compactness_rel"] = ours.compactness / theirs;
  json["points"] = f.points.size();
  json["clusters"] = kClusters;
  json["attempts"] = kAttempts;
  json["max_iterations"] = kIterations;
  if (!device.empty()) json["device"] = device;
  return json;
}

bench::Json kmeans_cpu(const bench::Options& options) {
  KMeansCpu engine;
  return kmeans_case(options, engine, "");
}

bench::Json kmeans_vulkan(const bench::Options& options) {
  const auto context = relight::bench::timing_vulkan();
  KMeansVk engine(*context);
  return kmeans_case(options, engine, context->device_info().name);
}

/// The glossy sphere alone, with its true k_d, from the camera image.
SpecularProblem sphere_problem(const Frame& f) {
  const int blue = f.scene.material_index("glossy_blue");
  LabelImage ids(f.color.width(), f.color.height());
  for (std::size_t i = 0; i < ids.size(); ++i) ids.pixels()[i] = f.truth.material.pixels()[i] == blue + 1 ? 1 : 0;
  SpecularProblem problem;
  problem.kd = f.scene.materials[static_cast<std::size_t>(blue)].kd.cast<float>();
  problem.lights = f.lights;
  problem.samples = select_samples(f.color, f.positions, f.truth.normals, ids, 0, &f.estimate.highlights, 2048);
  return problem;
}

bench::Json specular_case(const bench::Options& options, SpecularMethod method) {
  const Frame& f = frame();
  BrdfOptions bo = options_for(f);
  bo.solver = method;
  const auto solver = method == SpecularMethod::Ceres ? make_ceres_solver() : make_nelder_mead_solver();
  Materials materials = f.estimate.materials;
  const double ms = bench::median_ms(
      [&] { fit_materials(f.color, &f.estimate.highlights, f.positions, f.truth.normals, f.lights, bo, *solver, materials); },
      options.repetitions);
  const SpecularProblem problem = sphere_problem(f);
  const SpecularFit fit = solver->fit(problem, bo.specular);
  const double sphere_ms = bench::median_ms([&] { (void)solver->fit(problem, bo.specular); }, options.repetitions);
  int fitted = 0;
  for (const MaterialParams& m : materials.clusters) fitted += m.fit_rms >= 0.f;
  return {{"ms", ms},
          {"clusters", materials.clusters.size()},
          {"clusters_fitted", fitted},
          {"ks_rel_error", std::abs(fit.ks - 0.6) / 0.6},
          {"n_rel_error", std::abs(fit.n - 80.0) / 80.0},
          {"sphere_ms", sphere_ms},
          {"sphere_samples", problem.samples.size()},
          {"moving_lights", bo.specular.moving_lights}};
}

bench::Json specular_nelder_mead(const bench::Options& options) { return specular_case(options, SpecularMethod::NelderMead); }
bench::Json specular_ceres(const bench::Options& options) { return specular_case(options, SpecularMethod::Ceres); }

bench::Json specular_objective_vulkan(const bench::Options& options) {
  const Frame& f = frame();
  const SpecularProblem problem = sphere_problem(f);
  SpecularOptions so;
  const std::vector<SpecularCandidate> grid = specular_start_grid(so, 24, 16);
  const auto context = relight::bench::timing_vulkan();
  SpecularObjectiveVk gpu(*context);
  std::vector<double> ours, theirs(grid.size());
  const bench::Comparison cmp = bench::compare_interleaved(
      [&] { ours = gpu.evaluate(problem, so, grid); },
      [&] {
        for (std::size_t i = 0; i < grid.size(); ++i) theirs[i] = specular_objective(problem, so, grid[i].ks, grid[i].n);
      },
      options.repetitions);
  double worst = 0.0;
  for (std::size_t i = 0; i < grid.size(); ++i) worst = std::max(worst, std::abs(ours[i] - theirs[i]) / theirs[i]);
  bench::Json json = bench::comparison_json(cmp, "cpu_objective");
  json["candidates"] = grid.size();
  json["samples"] = problem.samples.size();
  json["max_rel_diff"] = worst;
  json["device"] = context->device_info().name;
  return json;
}

bench::Json brdf_frame(const bench::Options& options) {
  const Frame& f = frame();
  const BrdfOptions bo = options_for(f);
  KMeansCpu engine;
  KMeansTracker tracker(bo.kmeans, bo.seed, 0);  // steady state: warm starts only
  const auto solver = make_nelder_mead_solver();
  BrdfFrame out;
  const double ms = bench::median_ms(
      [&] { estimate_brdf(f.color, f.positions, f.truth.normals, f.lights, bo, engine, tracker, *solver, out); },
      options.repetitions);
  // Every 5th frame also runs K-means from k-means++ seeds: the average cost per frame.
  KMeansTracker policy(bo.kmeans, bo.seed);
  const double policy_ms = bench::median_ms(
      [&] {
        for (int i = 0; i < 5; ++i) estimate_brdf(f.color, f.positions, f.truth.normals, f.lights, bo, engine, policy, *solver, out);
      },
      std::max(1, options.repetitions / 2)) / 5.0;
  return {{"ms", ms}, {"ms_with_random_runs", policy_ms}, {"width", 640}, {"height", 480}, {"solver", "nelder_mead"}};
}

}  // namespace

RELIGHT_BENCH_CASE("kmeans/cpu", kmeans_cpu);
RELIGHT_BENCH_CASE("kmeans/vulkan", kmeans_vulkan);
RELIGHT_BENCH_CASE("specular/nelder_mead", specular_nelder_mead);
RELIGHT_BENCH_CASE("specular/ceres", specular_ceres);
RELIGHT_BENCH_CASE("specular/objective_vulkan", specular_objective_vulkan);
RELIGHT_BENCH_CASE("brdf/frame", brdf_frame);
