// pipeline/replay_640x480: `relight replay` end to end on a synthetic 640x480 sequence with the
// shipped pebble and 64 VPLs, as the CLI builds it (capture, depth filter, normals, marker pose,
// lights, BRDF, DIR, colour mapping, composite, PNG/video/report outputs), with the per-stage
// median milliseconds. The goal is frames per second (>= 5 fps). The baseline is the
// same replay with the exact choices its speed-ups replace (`exact_replay`: the rendered mesh
// itself casts the shadow maps), run frame by frame alternately with ours in the same process;
// composite_max_diff / composite_mean_diff compare the two final pictures of every frame (8-bit
// levels) and composite_pixels_over_2 counts the pixels that differ by more than 2 levels.
// pipeline/replay_640x480_no_render: the same replay with nothing to render (`--no-object`: the
// geometry, pose and frame outputs; goal >= 10 fps).
// pipeline/replay_640x480_gpu and pipeline/replay_1024x768_gpu: the replay with 256 VPLs on the
// Vulkan device the backend policy chooses (`--backend auto`: every stage on a real GPU; on a
// CPU-type device such as lavapipe the per-pixel stages stay on the CPU), writing what a live
// session at 60 fps writes: report.json only (no per-frame PNGs, no video; their disk cost is
// pipeline/replay_640x480's). Goals >= 60 and >= 30 fps on a real GPU. The baseline is the same
// replay on the CPU (`--backend cpu`: the CPU twins of every stage), alternately frame by frame;
// composite_max_diff / mean_diff / pixels_over_2 compare the two pictures, so the case also says
// whether the GPU path paints what the CPU path paints. stages_gpu_ms holds the median GPU time
// of every stage that reports one, stages_on_device the stages whose buffers lived on the device.
// pipeline/replay_tum_640x480: the main job, `relight replay` with no arguments, on the embedded
// real TUM sample (looped): the pebble on the desk, lit by the light estimated from the frames,
// against the same exact_replay. Real frames cost what synthetic ones do not (an overexposed
// desk masked as highlight over whole regions, the camera's own motion blur on the rendered
// layer): this is the speed users meet on their recordings.
// The first frame (pipeline creation, shader compilation) is left out of the timings.
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include "bench.h"
#include "relight/synth/sequence.h"
#include "relight/truth/sequence_writer.h"
#include "replay.h"
#include "report.h"

namespace {

using namespace relight;

struct TempFolder {
  std::filesystem::path path = std::filesystem::temp_directory_path() /
                               ("relight-bench-pipeline-" + std::to_string(::getpid()));
  TempFolder() { std::filesystem::create_directories(path); }
  ~TempFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

/// Replay options for `sequence` writing into `out` (made), quietly.
app::ReplayOptions replay_options(const std::filesystem::path& sequence, const std::filesystem::path& out) {
  app::ReplayOptions replay;
  replay.sequence = sequence;
  replay.out = out;
  replay.quiet = true;
  std::filesystem::create_directories(replay.out);
  return replay;
}

void write_sequence(const std::filesystem::path& folder, int frames, int width = 640, int height = 480) {
  synth::SynthOptions synth;
  synth.frames = frames;
  synth.ground_truth = false;
  synth.width = width;
  synth.height = height;
  truth::write_sequence(synth, folder);
}

/// The median of `values` after the first (pipeline creation, shader compilation).
double steady_median(const std::vector<double>& values) {
  const std::vector<double> steady(values.begin() + (values.empty() ? 0 : 1), values.end());
  return app::summarize(steady).median;
}

/// Per-stage medians of the frames after the first, of one of StageTimings' series: wall_ms,
/// cpu_ms (the process's CPU time while the stage ran) or device_ms (GPU time). Stages without
/// entries in the series (no GPU timestamps) are left out.
bench::Json stage_medians(const FrameGraph& graph, std::vector<double> StageTimings::*series = &StageTimings::wall_ms) {
  bench::Json stages = bench::Json::object();
  for (const auto& timing : graph.timings())
    if (!(timing.*series).empty()) stages[timing.stage] = steady_median(timing.*series);
  return stages;
}

/// The stages whose buffers lived on the device in their last run.
bench::Json stages_on_device(const FrameGraph& graph) {
  bench::Json stages = bench::Json::array();
  for (const auto& timing : graph.timings())
    if (timing.device_buffers || timing.backend == Backend::Vulkan) stages.push_back(timing.stage);
  return stages;
}

struct CompositeDifference {
  int max = 0;
  double sum = 0;
  std::size_t values = 0, pixels_over_2 = 0;

  void add(const ColorImage& a, const ColorImage& b) {
    if (a.width() != b.width() || a.height() != b.height()) throw Error("pipeline: the composites differ in size");
    for (std::size_t i = 0; i < a.pixels().size(); ++i) {
      const Rgb8 p = a.pixels()[i], q = b.pixels()[i];
      int pixel_max = 0;
      for (const int d : {std::abs(p.r - q.r), std::abs(p.g - q.g), std::abs(p.b - q.b)}) {
        pixel_max = std::max(pixel_max, d);
        sum += d;
      }
      values += 3;
      max = std::max(max, pixel_max);
      if (pixel_max > 2) ++pixels_over_2;
    }
  }
};

/// Runs `ours` and `baseline` frame by frame alternately (`frames` timed frames each), finishes
/// both and returns the fields both comparison cases share: times, fps, the composite difference
/// and the per-stage medians.
bench::Json compare_replays(app::ReplayPipeline& ours, app::ReplayPipeline& baseline, int frames,
                            const std::string& case_name, const std::string& baseline_name) {
  CompositeDifference difference;
  const auto run = [&](app::ReplayPipeline& pipeline) {
    if (!pipeline.graph->run_frame()) throw Error(case_name + ": the sequence ended early");
  };
  const bench::Comparison comparison =
      bench::compare_interleaved([&] { run(ours); },
                                 [&] {
                                   run(baseline);
                                   const ColorImage* a = ours.graph->find(ours.final_composite);
                                   const ColorImage* b = baseline.graph->find(baseline.final_composite);
                                   if (!a || !b) throw Error(case_name + ": no final composite");
                                   difference.add(*a, *b);
                                 },
                                 frames);
  ours.graph->finish();
  baseline.graph->finish();

  bench::Json result = bench::comparison_json(comparison, baseline_name);
  result["fps"] = 1000.0 / comparison.ms;
  result["baseline_fps"] = 1000.0 / comparison.baseline_ms;
  result["frames"] = frames;
  result["composite_max_diff"] = difference.max;
  result["composite_mean_diff"] = difference.values ? difference.sum / static_cast<double>(difference.values) : 0.0;
  result["composite_pixels_over_2"] = difference.pixels_over_2;
  result["compute"] = ours.compute;
  result["stages_ms"] = stage_medians(*ours.graph);
  result["stages_cpu_ms"] = stage_medians(*ours.graph, &StageTimings::cpu_ms);
  if (const auto steps = ours.dir ? app::dir_steps_json(*ours.dir) : std::nullopt)
    result["dir_steps_ms"] = (*steps)["median_ms"];
  result["baseline_stages_ms"] = stage_medians(*baseline.graph);
  return result;
}

/// The replay pipeline of `replay`, compiled.
app::ReplayPipeline compiled_pipeline(const app::ReplayOptions& replay) {
  auto pipeline = app::build_replay_pipeline(app::open_replay_source(replay), replay);
  pipeline.graph->compile();
  return pipeline;
}

/// The replay of `sequence` that `configure` sets up, with its coarse copy of the reconstruction
/// (ours, into folder/ours) against the same without it (exact_replay, into folder/exact).
bench::Json against_exact_replay(const std::filesystem::path& sequence, const std::filesystem::path& folder, int frames,
                                 const std::string& case_name,
                                 const std::function<void(app::ReplayOptions&)>& configure) {
  const auto build = [&](const std::string& name, int coarse_mesh_stride) {
    app::ReplayOptions replay = replay_options(sequence, folder / name);
    configure(replay);
    replay.coarse_mesh_stride = coarse_mesh_stride;
    return compiled_pipeline(replay);
  };
  auto ours = build("ours", app::ReplayOptions{}.coarse_mesh_stride);
  auto exact = build("exact", 1);
  return compare_replays(ours, exact, frames, case_name, "exact_replay");
}

bench::Json replay_640x480(const bench::Options& options) {
  TempFolder folder;
  const int frames = std::max(options.repetitions, 3);
  write_sequence(folder.path / "sequence", frames + 2);
  bench::Json result = against_exact_replay(folder.path / "sequence", folder.path, frames, "pipeline/replay_640x480",
                                            [](app::ReplayOptions& replay) {
                                              replay.objects = {app::data_folder() / "models" / "glossy_pebble.gltf"};
                                              replay.vpls = 64;
                                            });
  result["goal_fps"] = 5;
  return result;
}

bench::Json replay_tum_640x480(const bench::Options& options) {
  TempFolder folder;
  const int frames = std::max(options.repetitions, 3);
  // An empty sequence is the embedded sample: the main job.
  bench::Json result = against_exact_replay({}, folder.path, frames, "pipeline/replay_tum_640x480",
                                            [frames](app::ReplayOptions& replay) {
                                              replay.loops = (frames + 1 + 3) / 4;  // its 4 frames, looped
                                            });
  result["sequence"] = "data/tum_fr1_rpy (real, looped)";
  result["goal_fps"] = 5;
  return result;
}

bench::Json replay_640x480_no_render(const bench::Options& options) {
  TempFolder folder;
  write_sequence(folder.path / "sequence", std::max(options.repetitions, 3) + 1);
  app::ReplayOptions replay = replay_options(folder.path / "sequence", folder.path / "out");
  replay.no_object = true;
  auto pipeline = compiled_pipeline(replay);
  FrameGraph& graph = *pipeline.graph;
  if (!graph.run_frame()) throw Error("pipeline/replay_640x480_no_render: the sequence has no frames");
  const auto start = std::chrono::steady_clock::now();
  while (graph.run_frame()) {
  }
  graph.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto frames = graph.frames_run() - 1;

  bench::Json result;
  result["ms"] = 1000.0 * seconds / static_cast<double>(frames);
  result["fps"] = static_cast<double>(frames) / seconds;
  result["frames"] = frames;
  result["goal_fps"] = 10;
  result["compute"] = pipeline.compute;
  result["stages_ms"] = stage_medians(graph);
  return result;
}

/// The GPU cases at `width` x `height` (see the header).
bench::Json replay_gpu(const bench::Options& options, int width, int height, double goal_fps) {
  const std::string name = "pipeline/replay_" + std::to_string(width) + "x" + std::to_string(height) + "_gpu";
  TempFolder folder;
  const int frames = std::max(options.repetitions, 3);
  write_sequence(folder.path / "sequence", frames + 2, width, height);
  const auto build = [&](const std::string& side, vk::BackendPolicy backend) {
    app::ReplayOptions replay = replay_options(folder.path / "sequence", folder.path / side);
    replay.objects = {app::data_folder() / "models" / "glossy_pebble.gltf"};
    replay.vpls = 256;
    replay.backend = backend;
    replay.write_frames = false;
    replay.video = false;
    return compiled_pipeline(replay);
  };
  auto gpu = build("gpu", vk::BackendPolicy::Auto);
  auto cpu = build("cpu", vk::BackendPolicy::ForceCpu);
  bench::Json result = compare_replays(gpu, cpu, frames, name, "cpu_replay");
  result["goal_fps"] = goal_fps;
  result["vpls"] = 256;
  result["stages_gpu_ms"] = stage_medians(*gpu.graph, &StageTimings::device_ms);
  result["stages_on_device"] = stages_on_device(*gpu.graph);
  return result;
}

}  // namespace

RELIGHT_BENCH_CASE("pipeline/replay_640x480", replay_640x480);
RELIGHT_BENCH_CASE("pipeline/replay_640x480_no_render", replay_640x480_no_render);
RELIGHT_BENCH_CASE("pipeline/replay_tum_640x480", replay_tum_640x480);
RELIGHT_BENCH_CASE("pipeline/replay_640x480_gpu", [](const bench::Options& o) { return replay_gpu(o, 640, 480, 60); });
RELIGHT_BENCH_CASE("pipeline/replay_1024x768_gpu",
                   [](const bench::Options& o) { return replay_gpu(o, 1024, 768, 30); });
