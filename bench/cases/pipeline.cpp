// pipeline/replay_640x480: `relight replay` end to end on a synthetic 640x480 sequence with the
// shipped pebble and 64 VPLs, as the CLI builds it (capture, depth filter, normals, marker pose,
// lights, BRDF, DIR, colour mapping, composite, PNG/video/report outputs), with the per-stage
// median milliseconds. No baseline: this is the frames-per-second goal (>= 5 fps).
// The first frame (pipeline creation, shader compilation) is left out of the fps.
#include <chrono>
#include <filesystem>
#include <unistd.h>

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

bench::Json replay_640x480(const bench::Options& options) {
  TempFolder folder;
  synth::SynthOptions synth;
  synth.frames = std::max(options.repetitions, 3) + 1;
  synth.ground_truth = false;
  truth::write_sequence(synth, folder.path / "sequence");

  app::ReplayOptions replay;
  replay.sequence = folder.path / "sequence";
  replay.out = folder.path / "out";
  replay.quiet = true;
  replay.objects = {app::data_folder() / "models" / "glossy_pebble.gltf"};
  replay.vpls = 64;
  std::filesystem::create_directories(replay.out);
  auto pipeline = app::build_replay_pipeline(app::open_replay_source(replay), replay);
  FrameGraph& graph = *pipeline.graph;
  graph.compile();
  if (!graph.run_frame()) throw Error("pipeline/replay_640x480: the sequence has no frames");
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
  result["goal_fps"] = 5;
  result["compute"] = pipeline.compute;
  auto& stages = result["stages_ms"] = bench::Json::object();
  for (const auto& timing : graph.timings()) {
    std::vector<double> steady(timing.wall_ms.begin() + (timing.wall_ms.empty() ? 0 : 1), timing.wall_ms.end());
    stages[timing.stage] = app::summarize(steady).median;
  }
  return result;
}

}  // namespace

RELIGHT_BENCH_CASE("pipeline/replay_640x480", replay_640x480);
