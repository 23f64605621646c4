// Light extraction from the synthetic scene's 512x512 fisheye probe: importance sampling (CPU and
// Vulkan, 64 and 256 VPLs; goal <= 1 ms per frame on the CPU) and median cut. The probe geometry
// (per-pixel solid angle) is built once per sequence, so it is outside the timing.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "bench.h"
#include "relight/brdf/highlight.h"
#include "relight/brdf/light_estimation.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image_io.h"
#include "relight/lights/importance_sampling.h"
#include "relight/lights/light_smoothing.h"
#include "relight/lights/light_stages.h"
#include "relight/lights/median_cut.h"
#include "relight/lights/probe_stream_stage.h"
#include "relight/synth/light_animation.h"
#include "relight/synth/probe.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"

namespace {

using namespace relight;

struct Probe {
  RadianceImage image;
  lights::ProbeGeometry geometry;
};

const Probe& probe_512() {
  static const Probe probe = [] {
    const synth::Scene scene = synth::default_indoor_scene();
    const synth::LightProbe light_probe = synth::default_probe(scene);
    Probe p;
    p.image = synth::render_probe(scene, light_probe);
    lights::ProbeCalibration calibration;
    calibration.fisheye = light_probe.camera;
    p.geometry = lights::ProbeGeometry(calibration, p.image.width(), p.image.height());
    return p;
  }();
  return probe;
}

bench::Json importance_cpu(const bench::Options& options) {
  const Probe& p = probe_512();
  lights::ImportancePyramid pyramid;
  auto time = [&](int n) {
    return bench::median_ms(
        [&] {
          (void)lights::sample_importance(p.image, p.geometry, {n, 0}, pyramid);
        },
        options.repetitions);
  };
  return {{"ms", time(64)}, {"n_lights", 64}, {"ms_256", time(256)}, {"width", 512}, {"height", 512}};
}

bench::Json importance_vulkan(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const Probe& p = probe_512();
  lights::ImportanceSamplerVk sampler(*context, p.geometry);
  auto time = [&](int n) {
    return bench::median_ms([&] { (void)sampler.run(p.image, {n, 0}); }, options.repetitions);
  };
  const double ms = time(64);
  const double gpu_ms = sampler.last_gpu_ms().value_or(-1.0);
  return {{"ms", ms},       {"n_lights", 64}, {"gpu_ms", gpu_ms}, {"ms_256", time(256)},
          {"device", context->device_info().name}, {"unit", "ms per frame incl. upload and download"}};
}

bench::Json median_cut_cpu(const bench::Options& options) {
  const Probe& p = probe_512();
  const double ms = bench::median_ms([&] { (void)lights::median_cut(p.image, p.geometry, {64}); }, options.repetitions);
  return {{"ms", ms}, {"n_lights", 64}, {"width", 512}, {"height", 512}};
}

RELIGHT_BENCH_CASE("lights/importance_cpu", importance_cpu);
RELIGHT_BENCH_CASE("lights/importance_vulkan", importance_vulkan);
RELIGHT_BENCH_CASE("lights/median_cut_cpu", median_cut_cpu);

// lights/stream_640x480 (and _vulkan): the real light of every RGB-D frame as the product's graph
// makes it: the probe stream (a probe.txt list of 512x512 HDR probes of a light orbiting the
// table, one per 30 Hz frame) matched by timestamp and decoded, importance-sampled into 8 lights
// (the replay default) and smoothed. `ms` is the per-frame median of the three stages together.
namespace stream {

struct TempFolder {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("relight-bench-lights-" + std::to_string(::getpid()));
  TempFolder() { std::filesystem::create_directories(path); }
  ~TempFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

constexpr int kProbes = 8;

void write_probe_list(const std::filesystem::path& folder) {
  const synth::Scene scene = synth::default_indoor_scene();
  const synth::LightAnimationOptions orbit{.kind = synth::LightAnimation::Orbit, .orbit_degrees = 40};
  std::ofstream list(folder / "probe.txt");
  for (int i = 0; i < kProbes; ++i) {
    const synth::Scene frame = synth::scene_at_frame(scene, orbit, i, kProbes);
    const std::string name = "p" + std::to_string(i) + ".hdr";
    write_radiance(folder / name, synth::render_probe(frame, synth::default_probe(frame)));
    list << synth::frame_timestamp(i) << " " << name << "\n";
  }
}

class FrameClock final : public Stage {
 public:
  std::string name() const override { return "frame_clock"; }
  void declare(StageBuilder& builder) override { frame_ = builder.write(kSourceFrame); }
  void run(StageContext& context) override {
    // Loops over the list: the matcher rewinds, as for a looped replay.
    context.get(frame_).timestamp = synth::frame_timestamp(static_cast<int>(context.frame_index() % kProbes));
  }

 private:
  Write<FrameInfo> frame_;
};

class LightsSink final : public Stage {
 public:
  std::string name() const override { return "lights_sink"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override { lights_ = builder.read(lights::kLights); }
  void run(StageContext& context) override { count = context.get(lights_).lights.size(); }
  std::size_t count = 0;

 private:
  Read<lights::LightSet> lights_;
};

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

bench::Json run(const bench::Options& options, Backend backend) {
  std::unique_ptr<vk::VulkanContext> context;
  if (backend == Backend::Vulkan) {
    context = vk::try_create_vulkan();
    if (!context) return {{"skipped", "no Vulkan device"}};
  }
  TempFolder folder;
  write_probe_list(folder.path);
  FrameGraph graph(context ? &context->transfer() : nullptr);
  graph.emplace<FrameClock>();
  std::ostringstream warnings;
  auto& probe = graph.emplace<lights::ProbeStreamStage>(lights::open_probe_stream(folder.path, {}),
                                                        lights::ProbeMatchOptions{}, warnings);
  lights::LightExtractionOptions extraction;
  extraction.lights = 8;
  extraction.calibration.projection = lights::ProbeProjection::FromAspect;
  extraction.calibration.centred_on_image = true;
  graph.add(lights::make_light_extraction_stage(backend, context.get(), extraction));
  graph.emplace<lights::LightSmoothingStage>();
  auto& sink = graph.emplace<LightsSink>();
  graph.compile();
  const int frames = std::max(options.repetitions, 3) * kProbes;
  for (int i = 0; i < frames; ++i) graph.run_frame();
  std::vector<double> per_frame(static_cast<std::size_t>(frames), 0.0);
  bench::Json stages = bench::Json::object();
  for (const StageTimings& timings : graph.timings()) {
    if (timings.stage != "probe_stream" && timings.stage != "light_extraction" && timings.stage != "light_smoothing")
      continue;
    // The first lap decodes and builds the geometry once: left out like the pipeline's first frame.
    for (std::size_t i = 0; i < timings.wall_ms.size(); ++i) per_frame[i] += timings.wall_ms[i];
    stages[timings.stage + "_ms"] = median(timings.wall_ms);
  }
  per_frame.erase(per_frame.begin(), per_frame.begin() + kProbes);
  bench::Json result = {{"ms", median(per_frame)}, {"frames", frames - kProbes},
                        {"probe_width", 512},      {"probe_height", 512},
                        {"n_lights", sink.count},  {"probes_used", probe.matcher().probes_used()}};
  result.update(stages);
  if (context) result["device"] = context->device_info().name;
  return result;
}

}  // namespace stream

bench::Json stream_640x480(const bench::Options& options) { return stream::run(options, Backend::Cpu); }
bench::Json stream_640x480_vulkan(const bench::Options& options) { return stream::run(options, Backend::Vulkan); }

RELIGHT_BENCH_CASE("lights/stream_640x480", stream_640x480);

// lights/estimate_640x480: the real light without a probe (brdf/light_estimation.h), one
// add_frame per RGB-D frame of the synthetic room's static 640x480 view (highlights removed as
// the graph does; the accumulation grows over the first frames, then only the voxels' means
// change). `ms` is the per-frame median; the quality fields are the last estimate's dominant-light
// direction error against lamp 1 seen from the table and the table's irradiance error.
bench::Json estimate_640x480(const bench::Options& options) {
  const synth::Scene scene = synth::default_indoor_scene();
  const PinholeIntrinsics intrinsics = PinholeIntrinsics::kinect_v1();
  const Pose pose = synth::make_trajectory(synth::Trajectory::Static, 1, 0, scene)[0];
  const synth::RenderedFrame frame = synth::render_frame(scene, intrinsics, pose);
  PositionMap positions(intrinsics.width, intrinsics.height);
  for (int r = 0; r < intrinsics.height; ++r) {
    for (int c = 0; c < intrinsics.width; ++c) {
      const float z = frame.depth(r, c);
      if (z <= 0.f) continue;
      const Eigen::Vector3d p = intrinsics.unproject(c, r, z);
      positions(r, c) = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
    }
  }
  ColorImage cleaned;
  Mask highlights;
  brdf::remove_highlights(synth::encode_color(frame.radiance), {}, cleaned, highlights);
  brdf::LightEstimator estimator;
  const double ms =
      bench::median_ms([&] { estimator.add_frame(cleaned, &highlights, positions, frame.normals, intrinsics, pose); },
                       std::max(options.repetitions, 3));
  const brdf::LightEstimate& e = estimator.estimate();
  const Eigen::Vector3d truth = synth::unoccluded_irradiance(scene, scene.look_at, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d lamp = (scene.lights[0].position - scene.look_at).normalized();
  const double direction_error = std::acos(std::clamp(e.direction.dot(lamp), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  const double irradiance_error =
      lights::luminance(e.irradiance_at(Eigen::Vector3d::UnitZ())) / lights::luminance(truth) - 1.0;
  return {{"ms", ms},
          {"width", intrinsics.width},
          {"height", intrinsics.height},
          {"evidence", brdf::to_string(e.evidence)},
          {"direction_error_degrees", direction_error},
          {"irradiance_rel_error", irradiance_error},
          {"voxels", e.voxels}};
}

RELIGHT_BENCH_CASE("lights/estimate_640x480", estimate_640x480);
RELIGHT_BENCH_CASE("lights/stream_640x480_vulkan", stream_640x480_vulkan);

}  // namespace
