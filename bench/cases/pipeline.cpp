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
// The first frame (pipeline creation, shader compilation) is left out of the timings.
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>

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

void write_sequence(const std::filesystem::path& folder, int frames) {
  synth::SynthOptions synth;
  synth.frames = frames;
  synth.ground_truth = false;
  truth::write_sequence(synth, folder);
}

/// Per-stage medians of the frames after the first.
bench::Json stage_medians(const FrameGraph& graph) {
  bench::Json stages = bench::Json::object();
  for (const auto& timing : graph.timings()) {
    std::vector<double> steady(timing.wall_ms.begin() + (timing.wall_ms.empty() ? 0 : 1), timing.wall_ms.end());
    stages[timing.stage] = app::summarize(steady).median;
  }
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

bench::Json replay_640x480(const bench::Options& options) {
  TempFolder folder;
  const int frames = std::max(options.repetitions, 3);
  write_sequence(folder.path / "sequence", frames + 2);
  const auto build = [&](const std::string& name, int coarse_mesh_stride) {
    app::ReplayOptions replay = replay_options(folder.path / "sequence", folder.path / name);
    replay.objects = {app::data_folder() / "models" / "glossy_pebble.gltf"};
    replay.vpls = 64;
    replay.coarse_mesh_stride = coarse_mesh_stride;
    auto pipeline = app::build_replay_pipeline(app::open_replay_source(replay), replay);
    pipeline.graph->compile();
    return pipeline;
  };
  auto ours = build("ours", app::ReplayOptions{}.coarse_mesh_stride);
  auto exact = build("exact", 1);
  CompositeDifference difference;
  const auto run = [](app::ReplayPipeline& pipeline) {
    if (!pipeline.graph->run_frame()) throw Error("pipeline/replay_640x480: the sequence ended early");
  };
  const bench::Comparison comparison =
      bench::compare_interleaved([&] { run(ours); },
                                 [&] {
                                   run(exact);
                                   const ColorImage* a = ours.graph->find(ours.final_composite);
                                   const ColorImage* b = exact.graph->find(exact.final_composite);
                                   if (!a || !b) throw Error("pipeline/replay_640x480: no final composite");
                                   difference.add(*a, *b);
                                 },
                                 frames);
  ours.graph->finish();
  exact.graph->finish();

  bench::Json result = bench::comparison_json(comparison, "exact_replay");
  result["fps"] = 1000.0 / comparison.ms;
  result["baseline_fps"] = 1000.0 / comparison.baseline_ms;
  result["frames"] = frames;
  result["goal_fps"] = 5;
  result["composite_max_diff"] = difference.max;
  result["composite_mean_diff"] = difference.values ? difference.sum / static_cast<double>(difference.values) : 0.0;
  result["composite_pixels_over_2"] = difference.pixels_over_2;
  result["compute"] = ours.compute;
  result["stages_ms"] = stage_medians(*ours.graph);
  result["baseline_stages_ms"] = stage_medians(*exact.graph);
  return result;
}

bench::Json replay_640x480_no_render(const bench::Options& options) {
  TempFolder folder;
  write_sequence(folder.path / "sequence", std::max(options.repetitions, 3) + 1);
  app::ReplayOptions replay = replay_options(folder.path / "sequence", folder.path / "out");
  replay.no_object = true;
  auto pipeline = app::build_replay_pipeline(app::open_replay_source(replay), replay);
  FrameGraph& graph = *pipeline.graph;
  graph.compile();
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

}  // namespace

RELIGHT_BENCH_CASE("pipeline/replay_640x480", replay_640x480);
RELIGHT_BENCH_CASE("pipeline/replay_640x480_no_render", replay_640x480_no_render);
