// Robustness matrix, light probes and lights: `relight lights` on a probe with NaN / inf pixels,
// an all-black or all-saturated fisheye; a synthetic sequence whose own probe is black and a
// broken lights JSON under replay --object. Each is one error line naming the file, exit 1, no
// lights file and no preview. The probe stream: an unsorted list or a listed file missing is one
// error line; a black or saturated frame or an early end mid-stream is one warning and a finished run.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "inputs.h"
#include "outcome_checks.h"
#include "relight/core/image_io.h"

namespace relight::robustness {
namespace {

class ProbeRobustness : public ::testing::Test {
 protected:
  RunOutcome lights(const std::filesystem::path& probe, std::vector<std::string> extra = {}) {
    std::vector<std::string> arguments{"lights", probe.string(), "--n", "16", "--out", (out / "lights.json").string(),
                                       "--preview", (out / "lights.png").string(), "--quiet"};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return run_relight(arguments);
  }
  void expect_rejected(const std::filesystem::path& probe, const std::string& reason,
                       std::vector<std::string> extra = {}) {
    const auto run = lights(probe, std::move(extra));
    expect_clean_error(run, 1, probe.string() + ": ", out);
    EXPECT_NE(run.err.find(reason), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(out / "lights.json"));
    EXPECT_FALSE(std::filesystem::exists(out / "lights.png"));
  }
  /// A bright fisheye probe (a sky above a darker ground) with one pixel set to `bad`.
  std::filesystem::path exr_probe_with(float bad) {
    RadianceImage probe(64, 64, Float3{0.5f, 0.6f, 0.8f});
    for (int row = 40; row < 64; ++row)
      for (int col = 0; col < 64; ++col) probe(row, col) = Float3{0.1f, 0.1f, 0.1f};
    probe(20, 30) = Float3{bad, 1.f, 1.f};
    const auto file = dir.path() / "probe.exr";
    write_radiance(file, probe);
    return file;
  }
  std::filesystem::path eight_bit_probe(std::uint8_t value) {
    const auto file = dir.path() / ("probe_" + std::to_string(value) + ".png");
    write_color(file, ColorImage(96, 96, Rgb8{value, value, value}));
    return file;
  }
  test::TempDir dir;
  const std::filesystem::path out = dir.path() / "out";
  void SetUp() override { std::filesystem::create_directories(out); }
};

TEST_F(ProbeRobustness, NanInExr) {
  expect_rejected(exr_probe_with(std::numeric_limits<float>::quiet_NaN()), "not finite");
}

TEST_F(ProbeRobustness, InfinityInExr) {
  expect_rejected(exr_probe_with(std::numeric_limits<float>::infinity()), "not finite");
}

TEST_F(ProbeRobustness, AllBlackFisheye) {
  expect_rejected(eight_bit_probe(0), "no light", {"--projection", "fisheye"});
}

TEST_F(ProbeRobustness, AllSaturatedFisheye) {
  expect_rejected(eight_bit_probe(255), "saturated", {"--projection", "fisheye"});
}

TEST_F(ProbeRobustness, BlackHdrProbe) {
  const auto file = dir.path() / "black.hdr";
  write_radiance(file, RadianceImage(64, 32, Float3{0.f, 0.f, 0.f}));
  expect_rejected(file, "no light");
}

TEST_F(ProbeRobustness, TruncatedHdrProbe) {
  const auto file = dir.path() / "probe.hdr";
  std::filesystem::copy_file(kData / "probes" / "grace_latlong.hdr", file);
  truncate_file(file, 0.3);
  expect_rejected(file, "");
}

// A probe whose Radiance header claims 30 000 x 30 000 pixels (10.8 GB as float RGB) over a few
// bytes of data: refused from the header, naming the limit, with memory bounded.
TEST_F(ProbeRobustness, HdrProbeClaiming30000x30000Pixels) {
  const auto file = dir.path() / "huge.hdr";
  write_file_atomically(file,
                        std::string_view("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n\x02\x02\x75\x30"));
  const auto run = lights(file);
  expect_clean_error(run, 1, file.string() + ": a 30000x30000 ", out);
  EXPECT_NE(run.err.find("over the limit of"), std::string::npos) << run.err;
  expect_bounded_memory(run);
}

// replay --object on a synthetic sequence takes its lights from the sequence's probe.hdr.
TEST_F(ProbeRobustness, BlackSequenceProbeWhileRendering) {
  const auto sequence = copy_of_synthetic(dir.path() / "seq");
  write_radiance(sequence / "probe.hdr", RadianceImage(64, 64, Float3{0.f, 0.f, 0.f}));
  const auto run =
      run_relight({"replay", "--quiet", sequence.string(), "--object",
                   (kData / "models" / "glossy_pebble.gltf").string(), "--vpls", "8", "--out", out.string()});
  expect_clean_error(run, 1, (sequence / "probe.hdr").string() + ": ", out);
  EXPECT_FALSE(std::filesystem::exists(out / "composite.mp4"));
}

// The probe stream (probe.txt beside the frames): a broken list is named before any frame runs;
// a bad frame or an early end mid-stream keeps the last good probe, warns once and finishes.
class ProbeStreamRobustness : public ProbeRobustness {
 protected:
  std::filesystem::path sequence() {
    auto copy = dir.path() / "animated";
    if (!std::filesystem::exists(copy)) {
      std::filesystem::copy(animated_light_sequence(), copy, std::filesystem::copy_options::recursive);
    }
    return copy;
  }
  /// The listed probe files, in order.
  std::vector<std::string> listed(const std::filesystem::path& folder) {
    std::vector<std::string> lines;
    std::istringstream in(read_text_file(folder / "probe.txt"));
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] != '#') lines.push_back(line);
    return lines;
  }
  RunOutcome replay(const std::filesystem::path& folder) {
    return run_relight({"replay", "--quiet", folder.string(), "--object",
                        (kData / "models" / "glossy_pebble.gltf").string(), "--vpls", "8", "--no-video", "--out",
                        out.string()});
  }
  void expect_warned_once(const RunOutcome& run, const std::string& part) {
    expect_clean_success(run, out);
    EXPECT_EQ(count_lines_starting(run.err, "relight: warning: "), 1u) << describe(run);
    EXPECT_NE(run.err.find(part), std::string::npos) << describe(run);
    EXPECT_TRUE(std::filesystem::exists(out / "report.json"));
  }
};

TEST_F(ProbeStreamRobustness, UnsortedList) {
  const auto folder = sequence();
  const auto lines = listed(folder);
  write_file_atomically(folder / "probe.txt", lines[1] + "\n" + lines[0] + "\n" + lines[2] + "\n");
  expect_clean_error(replay(folder), 1, (folder / "probe.txt").string() + " line 2", out);
}

TEST_F(ProbeStreamRobustness, ListedFileMissing) {
  const auto folder = sequence();
  const std::string missing = listed(folder)[2].substr(listed(folder)[2].find(' ') + 1);
  std::filesystem::remove(folder / missing);
  expect_clean_error(replay(folder), 1, missing, out);
}

TEST_F(ProbeStreamRobustness, BlackFrameMidStream) {
  const auto folder = sequence();
  const std::string second = listed(folder)[1].substr(listed(folder)[1].find(' ') + 1);
  write_radiance(folder / second, RadianceImage(64, 64, Float3{0.f, 0.f, 0.f}));
  expect_warned_once(replay(folder), "black");
}

TEST_F(ProbeStreamRobustness, AllClippedFrameMidStream) {
  const auto folder = sequence();
  const auto lines = listed(folder);
  write_color(folder / "clipped.png", ColorImage(64, 64, Rgb8{255, 255, 255}));
  const std::string timestamp = lines[1].substr(0, lines[1].find(' '));
  write_file_atomically(folder / "probe.txt", lines[0] + "\n" + timestamp + " clipped.png\n" + lines[2] + "\n");
  expect_warned_once(replay(folder), "saturated");
}

TEST_F(ProbeStreamRobustness, StreamEndsEarly) {
  const auto folder = sequence();
  write_file_atomically(folder / "probe.txt", listed(folder)[0] + "\n");
  expect_warned_once(replay(folder), "ended");
}

// The lights of a recorded sequence come from a JSON file of `relight lights`: a broken one is
// named before any frame runs.
TEST_F(ProbeRobustness, MalformedLightsJson) {
  const auto sequence = kData / "tum_fr1_rpy";
  const auto pebble = (kData / "models" / "glossy_pebble.gltf").string();
  const auto overflowing = dir.path() / "overflowing.json";
  write_file_atomically(overflowing, std::string_view(R"({"lights": [{"type": "directional", "direction": [0, 0, 1],
                                                                   "power": [1e999, 1, 1]}]})"));
  const auto incomplete = dir.path() / "incomplete.json";
  write_file_atomically(incomplete, std::string_view(R"({"lights": [{"type": "point", "power": [1, 1, 1]}]})"));
  for (const auto& lights : {overflowing, incomplete}) {
    SCOPED_TRACE(lights.filename().string());
    const auto replay_out = dir.path() / ("out_" + lights.stem().string());
    expect_clean_error(run_relight({"replay", "--quiet", sequence.string(), "--object", pebble, "--place", "0,0,1",
                                    "--lights", lights.string(), "--out", replay_out.string()}),
                       1, lights.string() + ": ", replay_out);
  }
}

}  // namespace
}  // namespace relight::robustness
