// normals/*: method 1 (NormalsRawDepth) and method 2 (DepthWarpMerge + filtered normals) on
// the CPU against PCL's IntegralImageNormalEstimation (AVERAGE_3D_GRADIENT, max depth change
// 0.02, smoothing 10: the dissertation's comparison), and normals/pcl_omp (NormalEstimationOMP,
// k = 10) as its own line. Same process, same 640x480 synthetic frames (static camera, Kinect v1
// noise), angular error against the ray caster's exact normals on the last frame.
// common_*: both errors (mean and median) on the pixels where both methods have a normal, and
// the fraction of the true normals these pixels are; PCL leaves out discontinuities and borders.
// "ms" is one steady-state frame (the previous frame's outputs as history; method 1 on the CPU
// through a NormalsRawDepthCpu, as the stage runs it, whose scratch memory persists between
// frames); the errors are after 10 frames. Without PCL (libpcl-dev,
// scripts/debian-packages-bench.txt) the baseline fields are absent.
// normals/method1_vulkan: method 1 with every per-pixel pass on the GPU (NormalsRawDepthVk:
// cross products eq. 4.4–4.6, temporal blend eq. 4.7–4.8, hole filling) and pass 1's pyramid on
// the CPU; "ms" is one frame end to end (pyramid, buffer allocation, uploads, three dispatches,
// downloads), "gpu_ms" the dispatches alone (timestamp queries), "gpu_passes" names what ran
// on the GPU.
// normals/method2_*: method 2 as relight replay runs it: warp and merge, then method 1's
// estimator on the merged depth (the "filtered normal" of §4.3.3; NormalsDepthInput::Filtered);
// plain_angular_error_deg is the error of the stride-1 cross products of the same positions.
// normals/method2_vulkan: DepthWarpMergeVk (warp by compute scatter, merge) + NormalsRawDepthVk,
// the same fields as method1_vulkan.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bench.h"
#include "vulkan_timing.h"
#include "relight/reconstruct/cross_normals_vk.h"
#include "relight/reconstruct/depth_warp_merge.h"
#include "relight/reconstruct/depth_warp_merge_vk.h"
#include "relight/reconstruct/normal_error.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"
#include "relight/reconstruct/normals_raw_depth_vk.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"
#include "relight/synth/trajectory.h"
#include "relight/vk/context.h"
#include "relight/vk/device_selection.h"

#ifdef RELIGHT_HAVE_PCL
#include <pcl/features/integral_image_normal.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#endif

namespace {

using namespace relight;
using relight::bench::Json;

constexpr int kFrames = 10;

struct BenchSequence {
  PinholeIntrinsics intrinsics;
  std::vector<DepthMap> noisy;
  NormalMap truth;  // of the last frame
  Pose pose = Pose::Identity();
};

const BenchSequence& sequence() {
  static const BenchSequence data = [] {
    synth::SynthOptions options;  // 640x480
    BenchSequence s{synth::synth_intrinsics(options), {}, {}, {}};
    const synth::Scene scene = synth::default_indoor_scene();
    s.pose = synth::make_trajectory(synth::Trajectory::Static, 1, 0, scene).front();
    const synth::RenderedFrame truth = synth::render_frame(scene, s.intrinsics, s.pose);
    for (int i = 0; i < kFrames; ++i) {
      s.noisy.push_back(synth::apply_kinect_noise(truth.depth, truth.normals, s.intrinsics, options.kinect, 7,
                                                  static_cast<std::uint64_t>(i)));
    }
    s.truth = truth.normals;
    return s;
  }();
  return data;
}

#ifdef RELIGHT_HAVE_PCL
pcl::PointCloud<pcl::PointXYZ>::Ptr organised_cloud(const DepthMap& depth, const PinholeIntrinsics& k) {
  PositionMap positions;
  reconstruct::positions_from_depth(depth, k, positions);
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(depth.width(), depth.height());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Float3& p = positions.pixels()[i];
    (*cloud)[i] = p.z > 0.f ? pcl::PointXYZ(p.x, p.y, p.z) : pcl::PointXYZ(nan, nan, nan);
  }
  cloud->is_dense = false;
  return cloud;
}

NormalMap to_normal_map(const pcl::PointCloud<pcl::Normal>& normals, int width, int height) {
  NormalMap out(width, height);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto& n = normals[i];
    if (std::isfinite(n.normal_x) && std::isfinite(n.normal_y) && std::isfinite(n.normal_z)) {
      out.pixels()[i] = {n.normal_x, n.normal_y, n.normal_z};
    }
  }
  return out;
}

// PCL IntegralImage on the last noisy frame: the dissertation's baseline.
struct IntegralImageBaseline {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
  pcl::PointCloud<pcl::Normal> normals;
  explicit IntegralImageBaseline(const BenchSequence& s) : cloud(organised_cloud(s.noisy.back(), s.intrinsics)) {
    estimator.setNormalEstimationMethod(estimator.AVERAGE_3D_GRADIENT);
    estimator.setMaxDepthChangeFactor(0.02f);
    estimator.setNormalSmoothingSize(10.0f);
    estimator.setInputCloud(cloud);
  }
  void run() { estimator.compute(normals); }
  [[nodiscard]] NormalMap map(const BenchSequence& s) const {
    return to_normal_map(normals, s.intrinsics.width, s.intrinsics.height);
  }
};

// The baseline's error, and both errors on the pixels where both have a normal: PCL leaves out
// depth discontinuities and the image border, where normals are hardest, so the errors over each
// method's own pixels do not compare like for like.
void add_baseline(Json& json, const NormalMap& baseline, const NormalMap& ours, const NormalMap& truth) {
  const reconstruct::AngularError own = reconstruct::angular_error(baseline, truth);
  json["baseline_angular_error_deg"] = own.mean_deg;
  json["baseline_coverage"] = own.coverage;
  Mask both(truth.width(), truth.height());
  std::size_t true_normals = 0;
  for (std::size_t i = 0; i < both.size(); ++i) {
    both.pixels()[i] = is_valid_normal(baseline.pixels()[i]) && is_valid_normal(ours.pixels()[i]) ? 1 : 0;
    true_normals += is_valid_normal(truth.pixels()[i]) ? 1 : 0;
  }
  const reconstruct::AngularError ours_common = reconstruct::angular_error(ours, truth, &both);
  const reconstruct::AngularError baseline_common = reconstruct::angular_error(baseline, truth, &both);
  json["common_angular_error_deg"] = ours_common.mean_deg;
  json["baseline_common_angular_error_deg"] = baseline_common.mean_deg;
  json["common_median_error_deg"] = ours_common.median_deg;
  json["baseline_common_median_error_deg"] = baseline_common.median_deg;
  json["common_coverage"] =
      true_normals ? static_cast<double>(ours_common.compared) / static_cast<double>(true_normals) : 0.0;
}
#endif

// Times `ours` (and the PCL baseline when available) and fills the standard fields; `ours_normals`
// is what the errors are measured on.
Json compare_with_pcl(const std::function<void()>& ours, const NormalMap& ours_normals, const bench::Options& options) {
#ifdef RELIGHT_HAVE_PCL
  IntegralImageBaseline baseline(sequence());
  Json json = bench::comparison_json(bench::compare_interleaved(ours, [&] { baseline.run(); }, options.repetitions),
                                     "pcl_integral_image");
  add_baseline(json, baseline.map(sequence()), ours_normals, sequence().truth);
  return json;
#else
  (void)ours_normals;
  Json json;
  json["ms"] = bench::median_ms(ours, options.repetitions);
  json["baseline"] = "pcl_integral_image (not built: PCL not found)";
  return json;
#endif
}

Json method1_cpu(const bench::Options& options) {
  const BenchSequence& s = sequence();
  PositionMap positions[2];
  NormalMap normals[2];
  for (int i = 0; i < kFrames; ++i) {
    const int cur = i % 2, prev = 1 - cur;
    const reconstruct::NormalsHistory history{normals[prev], positions[prev], s.pose};
    reconstruct::normals_raw_depth(s.noisy[static_cast<std::size_t>(i)], s.intrinsics, s.pose,
                                   i > 0 ? &history : nullptr, {}, positions[cur], normals[cur]);
  }
  const int last = (kFrames - 1) % 2;
  const reconstruct::AngularError error = reconstruct::angular_error(normals[last], s.truth);
  // Steady state: frame 10 again with frame 9's outputs as history, into scratch outputs.
  const reconstruct::NormalsHistory history{normals[last], positions[last], s.pose};
  PositionMap scratch_positions;
  NormalMap scratch_normals;
  reconstruct::NormalsRawDepthCpu method;  // as the stage: scratch memory kept between frames
  Json json = compare_with_pcl(
      [&] { method.run(s.noisy.back(), s.intrinsics, s.pose, &history, {}, scratch_positions, scratch_normals); },
      normals[last], options);
  json["angular_error_deg"] = error.mean_deg;
  json["coverage"] = error.coverage;
  return json;
}

/// The fields every normals/*_vulkan line adds: the error after 10 frames, the median GPU time
/// of the dispatches (-1: no timestamp queries), the device and what ran on it.
void add_vulkan_fields(Json& json, const reconstruct::AngularError& error, std::vector<double>& gpu_ms,
                       const vk::VulkanContext& context, const char* passes) {
  json["angular_error_deg"] = error.mean_deg;
  json["coverage"] = error.coverage;
  std::sort(gpu_ms.begin(), gpu_ms.end());
  json["gpu_ms"] = gpu_ms.empty() ? -1.0 : gpu_ms[gpu_ms.size() / 2];
  json["device"] = context.device_info().name;
  json["device_type"] = vk::to_string(context.device_info().type);
  json["gpu_passes"] = passes;
}

Json method1_vulkan(const bench::Options& options) {
  const auto context = relight::bench::timing_vulkan();
  const BenchSequence& s = sequence();
  reconstruct::NormalsRawDepthVk gpu(*context);
  std::vector<double> gpu_ms;
  const auto frame = [&](const DepthMap& depth, const reconstruct::NormalsHistory* history, PositionMap& positions,
                         NormalMap& normals) {
    gpu.run(depth, s.intrinsics, s.pose, history, {}, positions, normals);
    if (const auto ms = gpu.last_gpu_ms()) gpu_ms.push_back(*ms);
  };
  PositionMap positions[2];
  NormalMap normals[2];
  for (int i = 0; i < kFrames; ++i) {
    const int cur = i % 2, prev = 1 - cur;
    const reconstruct::NormalsHistory history{normals[prev], positions[prev], s.pose};
    frame(s.noisy[static_cast<std::size_t>(i)], i > 0 ? &history : nullptr, positions[cur], normals[cur]);
  }
  const int last = (kFrames - 1) % 2;
  const reconstruct::AngularError error = reconstruct::angular_error(normals[last], s.truth);
  // Steady state: frame 10 again with frame 9's outputs as history, into scratch outputs.
  const reconstruct::NormalsHistory history{normals[last], positions[last], s.pose};
  PositionMap scratch_positions;
  NormalMap scratch_normals;
  gpu_ms.clear();
  Json json = compare_with_pcl([&] { frame(s.noisy.back(), &history, scratch_positions, scratch_normals); },
                               normals[last], options);
  add_vulkan_fields(json, error, gpu_ms, *context,
                    "positions + stride-4 cross products (eq. 4.4-4.6), temporal blend (eq. 4.7-4.8), "
                    "hole filling; pass 1 pyramid (eq. 4.1-4.3) on the CPU, uploaded");
  return json;
}

// Method 2 as the product runs it: warp and merge, then method 1's estimator on the merged depth
// (NormalsDepthInput::Filtered), both with the previous frame's outputs as history.
// "plain_angular_error_deg": the stride-1 cross products of the same merged positions.
struct Method2State {
  DepthMap filtered;
  reconstruct::DepthWeightMap weight;
  PositionMap positions;
  NormalMap normals;
};

/// Method 1's history from the previous frame's state (none on the first frame).
std::optional<reconstruct::NormalsHistory> history_of(const Method2State* previous, const BenchSequence& s) {
  if (!previous) return std::nullopt;
  return reconstruct::NormalsHistory{previous->normals, previous->positions, s.pose};
}

/// Runs `frame(depth, previous state or null, next state)` over the sequence's frames; returns
/// the last frame's state (one of `states`).
template <class Frame>
const Method2State& run_frames(const BenchSequence& s, Method2State (&states)[2], Frame&& frame) {
  for (int i = 0; i < kFrames; ++i) {
    frame(s.noisy[static_cast<std::size_t>(i)], i > 0 ? &states[1 - i % 2] : nullptr, states[i % 2]);
  }
  return states[(kFrames - 1) % 2];
}

double plain_normals_error(const Method2State& state, const BenchSequence& s) {
  PositionMap positions;
  NormalMap normals;
  reconstruct::positions_from_depth(state.filtered, s.intrinsics, positions);
  reconstruct::normals_from_positions(positions, normals);
  return reconstruct::angular_error(normals, s.truth).mean_deg;
}

Json method2_cpu(const bench::Options& options) {
  const BenchSequence& s = sequence();
  reconstruct::NormalsRawDepthCpu normals_method;  // as the stage: scratch memory kept between frames
  DepthMap warped;
  reconstruct::DepthWeightMap warped_weight;
  // One frame from `previous` (null: the first) into `next`.
  const auto frame = [&](const DepthMap& depth, const Method2State* previous, Method2State& next) {
    if (previous) {
      reconstruct::warp_depth(previous->filtered, previous->weight, s.intrinsics, Pose::Identity(), {}, warped,
                              warped_weight);
    } else {
      warped = DepthMap();  // no history: merge_depth takes the depth alone
    }
    reconstruct::merge_depth(depth, warped, warped_weight, {}, next.filtered, next.weight);
    const std::optional<reconstruct::NormalsHistory> history = history_of(previous, s);
    normals_method.run(next.filtered, s.intrinsics, s.pose, history ? &*history : nullptr, {}, next.positions,
                       next.normals);
  };
  Method2State states[2];
  const Method2State& last = run_frames(s, states, frame);
  const reconstruct::AngularError error = reconstruct::angular_error(last.normals, s.truth);
  Method2State scratch;
  Json json = compare_with_pcl([&] { frame(s.noisy.back(), &last, scratch); }, last.normals, options);
  json["angular_error_deg"] = error.mean_deg;
  json["coverage"] = error.coverage;
  json["plain_angular_error_deg"] = plain_normals_error(last, s);
  // The two halves on their own: warp + merge, and the normals of the merged depth.
  json["warp_ms"] = bench::median_ms(
      [&] {
        reconstruct::warp_depth(last.filtered, last.weight, s.intrinsics, Pose::Identity(), {}, warped, warped_weight);
      },
      options.repetitions);
  json["merge_ms"] = bench::median_ms(
      [&] { reconstruct::merge_depth(s.noisy.back(), warped, warped_weight, {}, scratch.filtered, scratch.weight); },
      options.repetitions);
  const reconstruct::NormalsHistory history{last.normals, last.positions, s.pose};
  json["normals_ms"] = bench::median_ms(
      [&] { normals_method.run(scratch.filtered, s.intrinsics, s.pose, &history, {}, scratch.positions, scratch.normals); },
      options.repetitions);
  return json;
}

Json method2_vulkan(const bench::Options& options) {
  const auto context = relight::bench::timing_vulkan();
  const BenchSequence& s = sequence();
  reconstruct::DepthWarpMergeVk warp_merge(*context);
  reconstruct::NormalsRawDepthVk normals_method(*context);
  std::vector<double> gpu_ms;
  const auto frame = [&](const DepthMap& depth, const Method2State* previous, Method2State& next) {
    warp_merge.run(depth, previous ? &previous->filtered : nullptr, previous ? &previous->weight : nullptr, s.intrinsics,
                   Pose::Identity(), {}, next.filtered, next.weight);
    const std::optional<reconstruct::NormalsHistory> history = history_of(previous, s);
    normals_method.run(next.filtered, s.intrinsics, s.pose, history ? &*history : nullptr, {}, next.positions,
                       next.normals);
    if (warp_merge.last_gpu_ms() && normals_method.last_gpu_ms()) {
      gpu_ms.push_back(*warp_merge.last_gpu_ms() + *normals_method.last_gpu_ms());
    }
  };
  Method2State states[2];
  const Method2State& last = run_frames(s, states, frame);
  const reconstruct::AngularError error = reconstruct::angular_error(last.normals, s.truth);
  Method2State scratch;
  gpu_ms.clear();
  Json json = compare_with_pcl([&] { frame(s.noisy.back(), &last, scratch); }, last.normals, options);
  add_vulkan_fields(json, error, gpu_ms, *context,
                    "warp (z-buffer clear, depth scatter by atomic min, weight scatter), merge; on the merged depth "
                    "positions + stride-4 cross products, temporal blend, hole filling (pass 1 pyramid on the CPU)");
  json["plain_angular_error_deg"] = plain_normals_error(last, s);
  return json;
}

#ifdef RELIGHT_HAVE_PCL
Json pcl_omp(const bench::Options& options) {
  const BenchSequence& s = sequence();
  const auto organised = organised_cloud(s.noisy.back(), s.intrinsics);
  auto dense = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  std::vector<std::size_t> pixel_of;
  for (std::size_t i = 0; i < organised->size(); ++i) {
    if (std::isfinite((*organised)[i].z)) {
      dense->push_back((*organised)[i]);
      pixel_of.push_back(i);
    }
  }
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimator;
  estimator.setInputCloud(dense);
  estimator.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  estimator.setKSearch(10);
  estimator.setViewPoint(0.f, 0.f, 0.f);  // orient towards the camera
  pcl::PointCloud<pcl::Normal> normals;
  const double ms = bench::median_ms([&] { estimator.compute(normals); }, std::max(1, options.repetitions / 2));
  NormalMap map(s.intrinsics.width, s.intrinsics.height);
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const auto& n = normals[i];
    if (std::isfinite(n.normal_x)) map.pixels()[pixel_of[i]] = {n.normal_x, n.normal_y, n.normal_z};
  }
  const reconstruct::AngularError error = reconstruct::angular_error(map, s.truth);
  Json json;
  json["ms"] = ms;
  json["angular_error_deg"] = error.mean_deg;
  json["coverage"] = error.coverage;
  json["k"] = 10;
  return json;
}
#endif

}  // namespace

RELIGHT_BENCH_CASE("normals/method1_cpu", method1_cpu);
RELIGHT_BENCH_CASE("normals/method1_vulkan", method1_vulkan);
RELIGHT_BENCH_CASE("normals/method2_cpu", method2_cpu);
RELIGHT_BENCH_CASE("normals/method2_vulkan", method2_vulkan);
#ifdef RELIGHT_HAVE_PCL
RELIGHT_BENCH_CASE("normals/pcl_omp", pcl_omp);
#endif
