// Fuzzes `--config cfg.json` (app/json_config.h): the input is the config file, read the way
// `relight` reads it (JsonConfig on the main app, unknown keys an error, fallthrough so that
// `relight replay --config` reaches it) by an app with the kinds of options relight's
// subcommands have: text, paths, repeatable values, integers and numbers with range checks,
// choices, flags, negated flags and flag callbacks. CLI11's parse errors are the answer to a bad
// config (main.cpp prints them as one line); any other exception, a crash or a sanitizer report
// is a finding.
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz_input.h"
#include "json_config.h"

namespace {

struct Options {
  std::filesystem::path out = "relight-out";
  std::string frames;
  bool quiet = false;
  bool video = true;
  std::string backend = "auto";
  std::string colormap = "stats";
  std::vector<std::filesystem::path> objects;
  std::vector<std::string> places;
  int vpls = 64;
  float exposure = 1.f;
  std::vector<float> white_balance;
  unsigned seed = 1;
};

void add_replay(CLI::App& app, Options& options) {
  CLI::App* replay = app.add_subcommand("replay", "replay");
  replay->add_option("sequence", options.out, "sequence");
  replay->add_option("--out", options.out, "out")->capture_default_str();
  replay->add_option("--frames", options.frames, "frames");
  replay->add_flag("--quiet", options.quiet, "quiet");
  replay->add_flag("!--no-video", options.video, "no video");
  replay->add_option("--backend", options.backend, "backend")->capture_default_str();
  replay->add_flag_callback("--cpu", [&options] { options.backend = "cpu"; }, "cpu");
  replay->add_option("--colormap", options.colormap, "colormap")->check(CLI::IsMember({"none", "sample", "stats"}));
  replay->add_option("--object", options.objects, "objects");
  replay->add_option("--place", options.places, "places");
  replay->add_option("--vpls", options.vpls, "vpls")->check(CLI::Range(0, 4096));
  replay->add_option("--exposure", options.exposure, "exposure")->check(CLI::PositiveNumber);
}

void add_synth(CLI::App& app, Options& options) {
  CLI::App* synth = app.add_subcommand("synth", "synth");
  synth->add_option("--out", options.out, "out");
  synth->add_option("--frames", options.vpls, "frames")->check(CLI::Range(1, 100000));
  synth->add_option("--white-balance", options.white_balance, "gains")->expected(3);
  synth->add_option("--seed", options.seed, "seed");
}

void parse_with_config(const char* subcommand, const std::filesystem::path& config) {
  CLI::App app{"relight"};
  app.require_subcommand(1);
  relight::app::add_json_config(app);
  app.allow_config_extras(CLI::config_extras_mode::error);
  app.fallthrough();
  Options options;
  add_replay(app, options);
  add_synth(app, options);
  const std::string config_text = config.string();
  const char* argv[] = {"relight", subcommand, "--config", config_text.c_str()};
  try {
    app.parse(static_cast<int>(std::size(argv)), argv);
  } catch (const CLI::ParseError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto config = relight::fuzz::scratch().write("config.json", relight::fuzz::as_text(data, size));
  parse_with_config("replay", config);
  parse_with_config("synth", config);
  return 0;
}
