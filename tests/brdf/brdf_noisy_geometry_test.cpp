// BRDF estimation on reconstructed geometry. A static camera looks at the synthetic scene
// (640x480) for ten frames; each frame's depth carries Kinect v1 noise (synth/kinect_noise.h),
// positions come from that noisy depth and normals from reconstruction method 1
// (reconstruct/normals_raw_depth.h, its temporal filter running over the frames), and
// estimate_brdf() runs every frame on those, the exact lights and the 8-bit camera image, with
// K-means warm-started by its tracker. The last frame is checked against the truth.
//
// The issue asks for n within 20 % on the glossy sphere (k_s 0.6, n 80) with Kinect noise and
// estimated normals. That is NOT met: with method 1's normals the fit gives n ~24 and k_s ~0.07
// (measured below). The cause is the normals, not the positions or the solver:
//   - noisy positions with exact normals: k_s and n stay within 10 % (KinectPositionsAlone...);
//   - the n = 80 lobe is ~4.5 degrees wide in normal space and its core is clipped in the 8-bit
//     image, so the fit sees only the lobe's steep flanks, where the model's value changes by
//     ~30 % per half degree of normal error. Least squares with noisy normals (errors in the
//     regressors) then flattens the lobe and lowers k_s: Gaussian normal noise of 0.25 / 0.5 / 1
//     degree per axis gives n 75.5 / 70.1 / 60.6 and k_s 0.51 / 0.40 / 0.25
//     (NormalNoiseTolerance...; over nine noise draws n is 2-10 % low at 0.25 degree and
//     24-51 % low at 1 degree, k_s 7-27 % and 58-76 % low). n within 20 % needs the sphere's
//     normals within a quarter to half a degree, k_s within 10 % even better ones;
//   - method 1's normals on the sphere are ~5 degrees off (mean 5.2, median 3.5, after ten
//     frames), and several degrees on exact depth too: one frame of exact depth gives 3.9 (the
//     stride-4 differences span 8 pixels of a sphere of 27 pixels radius), ten frames 7.9 (the
//     history lookup, a coarse texel, blurs the curved normal field). Before the central
//     differences and the block-centred history texels (reconstruct/normals_raw_depth.h) the
//     figures were 6.9 degrees with noise, 9.1 and 11.5 on exact depth, and the fit gave n ~19.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>

#include "brdf_test_scene.h"
#include "relight/brdf/brdf_stages.h"
#include "relight/reconstruct/normal_error.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/sequence.h"

namespace relight::brdf {
namespace {

constexpr int kFrames = 10;
constexpr std::uint64_t kNoiseSeed = 7;

/// The static camera's view: ground truth, the 8-bit camera image and the exact lights.
struct View {
  synth::Scene scene;
  synth::SynthOptions synth;  ///< 640x480, Kinect v1 noise
  PinholeIntrinsics intrinsics;
  Pose camera_to_world;
  synth::RenderedFrame truth;
  ColorImage color;
  ShadingLights lights;
};

const View& view() {
  static const View v = [] {
    View v;
    v.scene = synth::default_indoor_scene();
    v.intrinsics = synth::synth_intrinsics(v.synth);
    v.camera_to_world = synth::make_trajectory(synth::Trajectory::Static, 1, 0, v.scene)[0];
    v.truth = synth::render_frame(v.scene, v.intrinsics, v.camera_to_world);  // every frame sees this
    v.color = synth::encode_color(v.truth.radiance);
    v.lights = to_camera_frame(test::light_set_of(v.scene), v.camera_to_world, v.scene.environment.cast<float>());
    return v;
  }();
  return v;
}

DepthMap noisy_depth(const View& v, int frame) {
  return synth::apply_kinect_noise(v.truth.depth, v.truth.normals, v.intrinsics, v.synth.kinect, kNoiseSeed,
                                   static_cast<std::uint64_t>(frame));
}

BrdfOptions scene_options(const View& v) {
  BrdfOptions options;
  options.ambient = v.scene.environment.cast<float>();
  return options;
}

/// The last of kFrames frames of method 1 and estimate_brdf (Nelder-Mead) on Kinect depth.
struct NoisyRun {
  PositionMap positions;  ///< from the last frame's noisy depth
  NormalMap normals;      ///< method 1 after kFrames frames
  BrdfFrame estimate;
  double ms_per_frame = 0.0;  ///< estimate_brdf alone
};

NoisyRun run_noisy_sequence(const View& v) {
  const BrdfOptions options = scene_options(v);
  KMeansCpu engine;
  KMeansTracker tracker(options.kmeans, options.seed);
  const auto solver = make_nelder_mead_solver();
  PositionMap positions[2];
  NormalMap normals[2];
  NoisyRun run;
  double ms = 0.0;
  for (int f = 0; f < kFrames; ++f) {
    const int cur = f % 2, prev = 1 - cur;
    const reconstruct::NormalsHistory history{normals[prev], positions[prev], v.camera_to_world};
    reconstruct::normals_raw_depth(noisy_depth(v, f), v.intrinsics, v.camera_to_world, f > 0 ? &history : nullptr, {},
                                   positions[cur], normals[cur]);
    const auto start = std::chrono::steady_clock::now();
    estimate_brdf(v.color, positions[cur], normals[cur], v.lights, options, engine, tracker, *solver, run.estimate);
    ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  run.positions = std::move(positions[(kFrames - 1) % 2]);
  run.normals = std::move(normals[(kFrames - 1) % 2]);
  run.ms_per_frame = ms / kFrames;
  return run;
}

// Materials with the same albedo (floor/table wood, wall/tag white) cannot be told apart from
// k_d, so the cluster map is compared with the albedo class: the first material with that albedo.
int albedo_class(const synth::Scene& scene, int id) {
  const Eigen::Vector3d kd = scene.materials[static_cast<std::size_t>(id - 1)].kd;
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    if (scene.materials[m].kd == kd) return static_cast<int>(m);
  }
  return -1;
}

/// Adjusted Rand index of the cluster map against the albedo classes, over the pixels that have both.
double cluster_map_ari(const View& v, const Materials& m) {
  std::vector<int> estimated, truth;
  for (std::size_t i = 0; i < m.ids.size(); ++i) {
    const int id = v.truth.material.pixels()[i];
    if (id == 0 || m.ids.pixels()[i] == 0) continue;
    estimated.push_back(m.ids.pixels()[i]);
    truth.push_back(albedo_class(v.scene, id));
  }
  return adjusted_rand_index(estimated, truth);
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

int sphere_id(const View& v) { return test::material_id(v.scene, "glossy_blue"); }
const synth::Material& sphere_truth(const View& v) {
  return v.scene.materials[static_cast<std::size_t>(sphere_id(v) - 1)];
}

struct SphereResult {
  MaterialParams params;
  double kd_error = 1.0;  ///< largest channel difference to the true k_d
  double ks_rel = 1.0, n_rel = 1.0;
  double purity = 0.0;    ///< share of the cluster's pixels that are the sphere's
};

// The glossy sphere's material: the cluster holding most of the sphere's pixels.
SphereResult glossy_sphere(const View& v, const Materials& m) {
  std::map<int, int> votes;
  for (std::size_t i = 0; i < m.ids.size(); ++i) {
    if (v.truth.material.pixels()[i] == sphere_id(v) && m.ids.pixels()[i] != 0) ++votes[m.ids.pixels()[i]];
  }
  if (votes.empty()) {
    ADD_FAILURE() << "no cluster covers the glossy sphere";
    return {};
  }
  const auto [label, sphere_pixels] = *std::max_element(
      votes.begin(), votes.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  const synth::Material& truth = sphere_truth(v);
  SphereResult r;
  r.params = m.clusters[static_cast<std::size_t>(label - 1)];
  r.kd_error = (r.params.kd - truth.kd.cast<float>()).cwiseAbs().maxCoeff();
  r.ks_rel = rel(r.params.ks, truth.ks);
  r.n_rel = rel(r.params.n, truth.n);
  r.purity = static_cast<double>(sphere_pixels) / std::max(1, r.params.pixels);
  return r;
}

void print(const char* what, const SphereResult& r, double ari) {
  std::printf("%s: sphere kd (%.3f %.3f %.3f) error %.3f, ks %.3f (rel %.3f), n %.1f (rel %.3f), rms %.4f, "
              "%d px (purity %.3f); ARI %.3f\n",
              what, r.params.kd.x(), r.params.kd.y(), r.params.kd.z(), r.kd_error, r.params.ks, r.ks_rel, r.params.n,
              r.n_rel, r.params.fit_rms, r.params.pixels, r.purity, ari);
}

TEST(BrdfNoisyGeometry, KinectPositionsAloneKeepTheGlossySphereWithinTenPercent) {
  // The last frame's noisy positions with the exact normals, through the whole estimation.
  const View& v = view();
  PositionMap positions;
  reconstruct::positions_from_depth(noisy_depth(v, kFrames - 1), v.intrinsics, positions);
  const BrdfOptions options = scene_options(v);
  KMeansCpu engine;
  KMeansTracker tracker(options.kmeans, options.seed);
  BrdfFrame out;
  estimate_brdf(v.color, positions, v.truth.normals, v.lights, options, engine, tracker, *make_nelder_mead_solver(),
                out);
  const SphereResult r = glossy_sphere(v, out.materials);
  print("noisy positions, exact normals", r, cluster_map_ari(v, out.materials));
  EXPECT_LT(r.ks_rel, 0.10);    // measured 0.005
  EXPECT_LT(r.n_rel, 0.10);     // measured 0.000 (80.0)
  EXPECT_LT(r.kd_error, 0.02);  // measured 0.000
}

TEST(BrdfNoisyGeometry, Method1NormalsOnKinectDepth) {
  const View& v = view();
  const NoisyRun run = run_noisy_sequence(v);
  Mask sphere(v.intrinsics.width, v.intrinsics.height);
  for (std::size_t i = 0; i < sphere.size(); ++i) sphere.pixels()[i] = v.truth.material.pixels()[i] == sphere_id(v);
  const reconstruct::AngularError on_sphere = reconstruct::angular_error(run.normals, v.truth.normals, &sphere);
  const reconstruct::AngularError everywhere = reconstruct::angular_error(run.normals, v.truth.normals);
  std::printf("method 1 normals after %d frames: sphere mean %.2f deg (median %.2f), scene mean %.2f deg; "
              "estimate_brdf %.1f ms per frame\n",
              kFrames, on_sphere.mean_deg, on_sphere.median_deg, everywhere.mean_deg, run.ms_per_frame);
  for (const MaterialParams& c : run.estimate.materials.clusters) {
    std::printf("  cluster kd (%.3f %.3f %.3f) ks %.3f n %.1f rms %.4f pixels %d\n", c.kd.x(), c.kd.y(), c.kd.z(), c.ks,
                c.n, c.fit_rms, c.pixels);
  }
  const double ari = cluster_map_ari(v, run.estimate.materials);
  for (const auto& [name, solver] : {std::pair{"nelder-mead", SpecularMethod::NelderMead},
                                     std::pair{"ceres", SpecularMethod::Ceres}}) {
    Materials m = run.estimate.materials;
    if (solver == SpecularMethod::Ceres) {
      BrdfOptions options = scene_options(v);
      options.solver = solver;
      fit_materials(v.color, &run.estimate.highlights, run.positions, run.normals, v.lights, options,
                    *make_ceres_solver(), m);
    }
    const SphereResult r = glossy_sphere(v, m);
    print(name, r, ari);
    // The "n within 20 %" is not met here (see the header comment): measured n 23.8
    // (Nelder-Mead) and 23.9 (Ceres), k_s 0.069 and 0.069. What holds: the sphere keeps a
    // cluster of its own and its k_d, although the normals make it ~5 % dark.
    EXPECT_GT(r.purity, 0.95) << name;    // measured 1.000
    EXPECT_LT(r.kd_error, 0.06) << name;  // measured 0.030 (0.570 for 0.60 in blue)
  }
  // Lower than on exact geometry (0.73): far-wall pixels near the sensor's 4 m range get normals
  // tens of degrees off and a k_d of ~1.45, which takes a cluster, and the red box and the
  // yellow cylinder then share the wood's cluster.
  EXPECT_GT(ari, 0.55);  // measured 0.627
}

TEST(BrdfNoisyGeometry, NormalNoiseToleranceOfTheSpecularFit) {
  // Exact positions and the sphere's true k_d; exact normals with Gaussian angular noise.
  const View& v = view();
  PositionMap exact;
  reconstruct::positions_from_depth(v.truth.depth, v.intrinsics, exact);
  ColorImage cleaned;
  Mask highlights;
  remove_highlights(v.color, {}, cleaned, highlights);
  LabelImage ids(v.intrinsics.width, v.intrinsics.height);
  for (std::size_t i = 0; i < ids.size(); ++i) ids.pixels()[i] = v.truth.material.pixels()[i] == sphere_id(v) ? 1 : 0;
  const synth::Material& truth = sphere_truth(v);
  const auto solver = make_nelder_mead_solver();
  auto fit_with_noise = [&](double sigma_deg) {
    NormalMap normals = v.truth.normals;
    std::mt19937_64 rng(3);
    std::normal_distribution<float> gauss(0.f, static_cast<float>(sigma_deg * std::numbers::pi / 180.0));
    for (Float3& n : normals.pixels()) {
      if (!is_valid_normal(n)) continue;
      const Float3 noisy = n + Float3{gauss(rng), gauss(rng), gauss(rng)};
      n = (1.f / length(noisy)) * noisy;
    }
    SpecularProblem problem;
    problem.kd = truth.kd.cast<float>();
    problem.lights = v.lights;
    problem.samples = select_samples(v.color, exact, normals, ids, 0, &highlights, 2048);
    const SpecularFit fit = solver->fit(problem, {});
    std::printf("normal noise %.2f deg per axis: ks %.3f (rel %.3f), n %.1f (rel %.3f), rms %.4f\n", sigma_deg, fit.ks,
                rel(fit.ks, truth.ks), fit.n, rel(fit.n, truth.n), fit.rms);
    return fit;
  };
  const SpecularFit quarter = fit_with_noise(0.25);
  EXPECT_LT(rel(quarter.n, truth.n), 0.15);  // measured 0.056 (0.02-0.10 over nine draws; k_s 0.153 low)
  // For the record (header comment): half a degree and one degree (measured n rel 0.12 and
  // 0.24, k_s rel 0.33 and 0.59).
  (void)fit_with_noise(0.5);
  (void)fit_with_noise(1.0);
}

}  // namespace
}  // namespace relight::brdf
