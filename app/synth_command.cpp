// `relight synth`: writes a synthetic RGB-D sequence with ground truth (see synth/sequence.h).
#include <chrono>
#include <iostream>

#include "commands.h"
#include "relight/core/error.h"
#include "relight/core/progress.h"
#include "relight/synth/sequence.h"
#include "relight/truth/sequence_writer.h"

namespace relight::app {

namespace {

struct SynthCommandOptions {
  std::filesystem::path out;
  int frames = 30;
  std::string trajectory = "orbit";
  std::uint64_t seed = 0;
  std::string noise = "kinect1";
  std::vector<double> white_balance{1.0, 1.0, 1.0};
  double exposure = 1.0;
  int threads = 0;
  std::string size = "640x480";
  bool no_ground_truth = false;
  bool quiet = false;
};

int run_synth(const SynthCommandOptions& command) {
  synth::SynthOptions options;
  options.frames = command.frames;
  options.trajectory = synth::parse_trajectory(command.trajectory);
  options.noise = synth::parse_noise(command.noise);
  options.seed = command.seed;
  options.color.gains = {command.white_balance[0], command.white_balance[1], command.white_balance[2]};
  options.color.exposure = command.exposure;
  options.threads = command.threads;
  if (command.size == "320x240") {
    options.width = 320;
    options.height = 240;
  } else if (command.size != "640x480") {
    throw Error("--size '" + command.size + "' is not 640x480 or 320x240");
  }
  options.ground_truth = !command.no_ground_truth;

  ProgressBar progress("synth", command.frames, command.quiet);
  const auto start = std::chrono::steady_clock::now();
  truth::write_sequence(options, command.out, [&](int done, int) { progress.update(done); });
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!command.quiet) {
    std::cerr << "relight synth: " << command.frames << " frames in " << seconds << " s ("
              << seconds / command.frames << " s/frame) -> " << command.out.string() << "\n";
  }
  return 0;
}

}  // namespace

void register_synth(CLI::App& app, Runners& runners) {
  auto options = std::make_shared<SynthCommandOptions>();
  CLI::App* synth = app.add_subcommand("synth", "Write a synthetic RGB-D sequence with exact ground truth");
  synth->add_option("--out", options->out, "Output folder (TUM RGB-D layout + gt/, probe.hdr, scene.json)")
      ->required();
  synth->add_option("--frames", options->frames, "Number of frames")->check(CLI::Range(1, 100000))->capture_default_str();
  synth->add_option("--trajectory", options->trajectory, "Camera path: static, orbit or handheld")
      ->check(CLI::IsMember({"static", "orbit", "handheld"}))
      ->capture_default_str();
  synth->add_option("--seed", options->seed, "Random seed (noise, handheld path); same seed, same bytes")
      ->capture_default_str();
  synth->add_option("--noise", options->noise, "Depth noise: kinect1 or none")
      ->check(CLI::IsMember({"kinect1", "none"}))
      ->capture_default_str();
  synth->add_option("--white-balance", options->white_balance, "Colour camera gains R,G,B")
      ->expected(3)
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  synth->add_option("--exposure", options->exposure, "Colour camera exposure multiplier")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  synth->add_option("--size", options->size,
                    "Image size: 640x480 (Kinect v1) or 320x240 (its QVGA mode, the intrinsics halved)")
      ->check(CLI::IsMember({"640x480", "320x240"}))
      ->capture_default_str();
  synth->add_option("--threads", options->threads, "Render threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  synth->add_flag("--no-gt", options->no_ground_truth, "Skip the gt/ folder");
  synth->add_flag("--quiet", options->quiet, "No progress or summary on stderr");
  runners[synth] = [options] { return run_synth(*options); };
}

}  // namespace relight::app
