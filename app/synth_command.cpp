// `relight synth`: writes a synthetic RGB-D sequence with ground truth (see synth/sequence.h).
#include <chrono>
#include <iostream>

#include "commands.h"
#include "option_values.h"
#include "relight/core/error.h"
#include "relight/core/progress.h"
#include "relight/synth/sequence.h"
#include "relight/truth/sequence_writer.h"

namespace relight::app {

namespace {

/// The Kinect v1's two sizes.
enum class ImageSize { Vga, Qvga };
constexpr std::array<NamedValue<ImageSize>, 2> kImageSizeNames{
    {{"640x480", ImageSize::Vga}, {"320x240", ImageSize::Qvga}}};

struct SynthCommandOptions {
  std::filesystem::path out;
  int frames = 30;
  synth::Trajectory trajectory = synth::Trajectory::Orbit;
  std::uint64_t seed = 0;
  synth::NoiseModel noise = synth::NoiseModel::Kinect1;
  std::vector<double> white_balance{1.0, 1.0, 1.0};
  double exposure = 1.0;
  double color_blur = 0.0;
  std::vector<double> color_noise{0.0, 0.0};
  int threads = 0;
  ImageSize size = ImageSize::Vga;
  synth::LightAnimationOptions light_animation;
  double probe_noise = 0.0;
  bool no_ground_truth = false;
  bool quiet = false;
};

int run_synth(const SynthCommandOptions& command) {
  synth::SynthOptions options;
  options.frames = command.frames;
  options.trajectory = command.trajectory;
  options.noise = command.noise;
  options.seed = command.seed;
  options.color.gains = {command.white_balance[0], command.white_balance[1], command.white_balance[2]};
  options.color.exposure = command.exposure;
  options.camera.blur_sigma_px = command.color_blur;
  options.camera.noise_floor = command.color_noise[0];
  options.camera.noise_gain = command.color_noise[1];
  options.threads = command.threads;
  if (command.size == ImageSize::Qvga) {
    options.width = 320;
    options.height = 240;
  }
  options.ground_truth = !command.no_ground_truth;
  options.light_animation = command.light_animation;
  options.probe_noise = command.probe_noise;

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
  add_choice_option(*synth, "--trajectory", options->trajectory, synth::kTrajectoryNames, "Camera path");
  synth->add_option("--seed", options->seed, "Random seed (noise, handheld path); same seed, same bytes")
      ->capture_default_str();
  add_choice_option(*synth, "--noise", options->noise, synth::kNoiseModelNames, "Depth noise");
  synth->add_option("--white-balance", options->white_balance, "Colour camera gains R,G,B")
      ->expected(3)
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  synth->add_option("--exposure", options->exposure, "Colour camera exposure multiplier")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  synth
      ->add_option("--color-blur", options->color_blur,
                   "Colour camera's point spread: Gaussian sigma in pixels on the radiance (0 = sharp)")
      ->check(CLI::Range(0.0, 20.0))
      ->capture_default_str();
  synth
      ->add_option("--color-noise", options->color_noise,
                   "Colour camera's noise: FLOOR,GAIN of sigma(I)^2 = FLOOR + GAIN * I in 8-bit code values, per "
                   "channel, new every frame (0,0 = none)")
      ->expected(2)
      ->delimiter(',')
      ->check(CLI::NonNegativeNumber);
  add_choice_option(*synth, "--size", options->size, kImageSizeNames,
                    "Image size: 640x480 (Kinect v1) or 320x240 (its QVGA mode, the intrinsics halved)");
  add_choice_option(*synth, "--light-animation", options->light_animation.kind, synth::kLightAnimationNames,
                    "Real light that changes: the key light switches on or off at --light-event-frame, dims to "
                    "--light-dim-to, or orbits by --light-orbit-degrees; or pocket-lamp: a hand-held spot lamp "
                    "with a tag of its own (id 1) turns by --light-orbit-degrees (scene.json's pocket_lamp "
                    "gives the --real-spot-tag options that track it); writes probe.txt + probe/ (the probe "
                    "of every frame) and gt/lights/ (the true lights of every frame)");
  synth
      ->add_option("--light-event-frame", options->light_animation.event_frame,
                   "Frame at which the light switches (default: half way)")
      ->check(CLI::NonNegativeNumber);
  synth
      ->add_option("--light-dim-to", options->light_animation.dim_to,
                   "Last frame's intensity factor of --light-animation dim")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  synth
      ->add_option("--light-orbit-degrees", options->light_animation.orbit_degrees,
                   "Turn of the light about the table's vertical axis (orbit), or of the pocket lamp about its own "
                   "(pocket-lamp), over the sequence")
      ->capture_default_str();
  synth
      ->add_option("--light-orbit-height", options->light_animation.orbit_height,
                   "The orbiting light's height above the floor in metres (orbit; the table top is at 0.75; "
                   "default: the key light's own, 2.2): a low light casts long shadows")
      ->check(CLI::PositiveNumber);
  synth
      ->add_option("--probe-noise", options->probe_noise,
                   "The probe camera's sensor noise: relative standard deviation per pixel, new every frame "
                   "(writes probe.txt + probe/ with each frame's probe)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  synth->add_option("--threads", options->threads, "Render threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  synth->add_flag("--no-gt", options->no_ground_truth, "Skip the gt/ folder");
  synth->add_flag("--quiet", options->quiet, "No progress or summary on stderr");
  runners[synth] = [options] { return run_synth(*options); };
}

}  // namespace relight::app
