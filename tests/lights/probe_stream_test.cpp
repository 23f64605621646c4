// The probe stream: lists, still images, and matching probe frames to RGB-D timestamps.
#include "relight/lights/probe_stream.h"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "relight/core/error.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image_io.h"
#include "relight/lights/probe_stream_stage.h"
#include "temp_dir.h"

namespace relight::lights {
namespace {

namespace fs = std::filesystem;

// A small lat-long probe whose every pixel has radiance `value` (the frame's marker).
RadianceImage marker_probe(float value) {
  RadianceImage image(8, 4);
  for (Float3& p : image.pixels()) p = {value, value, value};
  return image;
}

// Writes probes with the given timestamps (probe i has radiance i + 1) and their list.
fs::path write_list(const fs::path& dir, const std::vector<double>& timestamps) {
  std::ofstream list(dir / "probe.txt");
  list << "# timestamp filename\n";
  for (std::size_t i = 0; i < timestamps.size(); ++i) {
    const std::string name = "p" + std::to_string(i) + ".hdr";
    write_radiance(dir / name, marker_probe(static_cast<float>(i + 1)));
    list << std::fixed << timestamps[i] << " " << name << "\n";
  }
  return dir / "probe.txt";
}

float marker(const RadianceImage& probe) { return probe(0, 0).x; }

TEST(ProbeStream, NearestFrameWithinTheTolerance) {
  test::TempDir dir;
  write_list(dir.path(), {10.00, 10.10, 10.20, 10.30});
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path(), {}), {.tolerance_s = 0.04}, warnings);
  EXPECT_EQ(marker(matcher.probe_for(10.01)), 1.f);
  EXPECT_EQ(marker(matcher.probe_for(10.08)), 2.f);  // nearer to 10.10 than to 10.00
  EXPECT_EQ(marker(matcher.probe_for(10.12)), 2.f);  // the same probe frame again
  EXPECT_EQ(marker(matcher.probe_for(10.29)), 4.f);  // 10.20 passed, 10.30 is nearer
  EXPECT_EQ(matcher.frames_kept(), 0);
  EXPECT_EQ(matcher.probes_used(), 3);
  EXPECT_TRUE(warnings.str().empty()) << warnings.str();
}

TEST(ProbeStream, AGapOrTheEndKeepsTheLastProbeAndSaysSoOnce) {
  test::TempDir dir;
  write_list(dir.path(), {1.0, 1.1, 2.0});
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path() / "probe.txt", {}), {.tolerance_s = 0.05}, warnings);
  EXPECT_EQ(marker(matcher.probe_for(1.1)), 2.f);
  EXPECT_EQ(marker(matcher.probe_for(1.5)), 2.f);  // no probe within 0.05 s: kept
  EXPECT_EQ(marker(matcher.probe_for(1.6)), 2.f);
  EXPECT_EQ(marker(matcher.probe_for(2.0)), 3.f);
  EXPECT_EQ(marker(matcher.probe_for(2.5)), 3.f);  // the stream ended
  EXPECT_EQ(marker(matcher.probe_for(2.6)), 3.f);
  EXPECT_EQ(matcher.frames_kept(), 4);
  const std::string text = warnings.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;
  EXPECT_NE(text.find("no frame within"), std::string::npos) << text;
  EXPECT_NE(text.find("ended"), std::string::npos) << text;
  const auto summary = matcher.summary();
  EXPECT_EQ(summary["frames_kept_last_probe"], 4);
  EXPECT_EQ(summary["kept_because"].dump(), R"(["gap","ended"])");
}

TEST(ProbeStream, BadFramesMidStreamKeepTheLastGoodProbe) {
  test::TempDir dir;
  write_list(dir.path(), {0.0, 0.1, 0.2, 0.3});
  write_radiance(dir.path() / "p1.hdr", marker_probe(0.f));             // black
  { std::ofstream(dir.path() / "p2.hdr") << "#?RADIANCE\ntruncated"; }  // unreadable
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path(), {}), {}, warnings);
  EXPECT_EQ(marker(matcher.probe_for(0.0)), 1.f);
  EXPECT_EQ(marker(matcher.probe_for(0.1)), 1.f);
  EXPECT_EQ(marker(matcher.probe_for(0.2)), 1.f);
  EXPECT_EQ(marker(matcher.probe_for(0.3)), 4.f);
  EXPECT_EQ(matcher.frames_kept(), 2);
  EXPECT_NE(warnings.str().find("black"), std::string::npos) << warnings.str();
  EXPECT_NE(warnings.str().find("p2.hdr"), std::string::npos) << warnings.str();
}

TEST(ProbeStream, ABadFirstProbeIsAnError) {
  test::TempDir dir;
  write_list(dir.path(), {0.0, 0.1});
  write_radiance(dir.path() / "p0.hdr", marker_probe(0.f));
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path(), {}), {}, warnings);
  EXPECT_THROW((void)matcher.probe_for(0.0), Error);
}

TEST(ProbeStream, ALoopedReplayStartsTheProbeStreamAgain) {
  test::TempDir dir;
  write_list(dir.path(), {5.0, 5.1, 5.2});
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path(), {}), {}, warnings);
  for (int loop = 0; loop < 2; ++loop) {
    EXPECT_EQ(marker(matcher.probe_for(5.0)), 1.f);
    EXPECT_EQ(marker(matcher.probe_for(5.1)), 2.f);
    EXPECT_EQ(marker(matcher.probe_for(5.2)), 3.f);
  }
  EXPECT_EQ(matcher.frames_kept(), 0);
}

TEST(ProbeStream, AStillImageServesEveryFrameAndIsReadOnce) {
  test::TempDir dir;
  write_radiance(dir.path() / "still.exr", marker_probe(7.f));
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path() / "still.exr", {}), {}, warnings);
  EXPECT_EQ(marker(matcher.probe_for(1.0)), 7.f);
  fs::remove(dir.path() / "still.exr");  // read once: later frames do not need the file
  EXPECT_EQ(marker(matcher.probe_for(100.0)), 7.f);
  EXPECT_EQ(matcher.probes_used(), 1);
  EXPECT_EQ(matcher.frames_kept(), 0);
}

TEST(ProbeStream, EightBitProbesAreDecodedAndClippingIsReported) {
  test::TempDir dir;
  ColorImage image(10, 10);
  for (Rgb8& p : image.pixels()) p = {60, 60, 60};
  for (int i = 0; i < 5; ++i) image(0, i) = {255, 255, 255};  // 5 % saturated
  write_color(dir.path() / "ldr.png", image);
  std::ostringstream warnings;
  ProbeMatcher matcher(open_probe_stream(dir.path() / "ldr.png", {}), {}, warnings);
  const RadianceImage& probe = matcher.probe_for(0.0);
  EXPECT_NEAR(probe(5, 5).x, ProbeResponse::srgb_inverse()[0][60], 1e-6);
  EXPECT_NEAR(probe(0, 0).x, ProbeResponse{}.clip_gain, 1e-4);
  EXPECT_NE(warnings.str().find("5 % of its pixels saturated"), std::string::npos) << warnings.str();
  EXPECT_DOUBLE_EQ(matcher.summary()["max_clipped_share"].get<double>(), 0.05);
}

// Found by probe_image_fuzzer: an OpenEXR probe may hold NaN, infinity or negative values, which
// no light is. NaN and infinity refuse the probe with a line naming the pixel; negatives become
// zero.
TEST(ProbeStream, OpenExrProbesWithNonFiniteValuesAreRefusedAndNegativesAreNoLight) {
  test::TempDir dir;
  RadianceImage image = marker_probe(2.f);
  image(1, 1) = {-0.5f, 3.f, -1e-3f};
  write_radiance(dir.path() / "negative.exr", image);
  const ProbeFrame frame = read_probe_image(dir.path() / "negative.exr", {});
  EXPECT_EQ(frame.radiance(1, 1).x, 0.f);
  EXPECT_EQ(frame.radiance(1, 1).y, 3.f);
  EXPECT_EQ(frame.radiance(1, 1).z, 0.f);
  EXPECT_EQ(frame.radiance(0, 0).x, 2.f);
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    image(2, 3) = {1.f, bad, 1.f};
    write_radiance(dir.path() / "bad.exr", image);
    try {
      (void)read_probe_image(dir.path() / "bad.exr", {});
      ADD_FAILURE() << "a probe with " << bad << " was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.exr: pixel (3, 2) is not finite"), std::string::npos) << e.what();
    }
  }
}

TEST(ProbeStream, BadListsAreOneLineErrorsNamingTheLine) {
  test::TempDir dir;
  write_list(dir.path(), {1.0, 2.0});
  const auto expect_error = [&](const std::string& list, const std::string& part) {
    { std::ofstream(dir.path() / "probe.txt") << list; }
    try {
      (void)open_probe_stream(dir.path(), {});
      ADD_FAILURE() << "accepted: " << list;
    } catch (const Error& error) {
      const std::string what = error.what();
      EXPECT_NE(what.find(part), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  expect_error("2.0 p0.hdr\n1.0 p1.hdr\n", "line 2");  // unsorted
  expect_error("1.0 p0.hdr\n2.0 missing.hdr\n", "missing.hdr");
  expect_error("1.0\n", "line 1");
  expect_error("# nothing\n", "lists no probe image");
  expect_error("1.0 notes.txt\n", "not a probe image");
  fs::remove(dir.path() / "probe.txt");
  EXPECT_THROW((void)open_probe_stream(dir.path(), {}), Error);         // a folder without a list
  EXPECT_EQ(open_probe_stream(dir.path() / "probe.mp4", {}), nullptr);  // for the video opener
}

// The stage in a graph: each frame's probe by the source frame's timestamp.
class TimestampSource final : public Stage {
 public:
  explicit TimestampSource(std::vector<double> timestamps) : timestamps_(std::move(timestamps)) {}
  std::string name() const override { return "source"; }
  void declare(StageBuilder& builder) override { frame_ = builder.write(kSourceFrame); }
  void run(StageContext& context) override {
    const auto i = static_cast<std::size_t>(context.frame_index());
    if (i >= timestamps_.size()) return context.end_of_stream();
    context.get(frame_).timestamp = timestamps_[i];
  }

 private:
  std::vector<double> timestamps_;
  Write<FrameInfo> frame_;
};

class ProbeRecorder final : public Stage {
 public:
  std::string name() const override { return "recorder"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override { probe_ = builder.read(kProbe); }
  void run(StageContext& context) override { markers.push_back(marker(context.get(probe_))); }
  std::vector<float> markers;

 private:
  Read<RadianceImage> probe_;
};

TEST(ProbeStreamStage, WritesEachFramesProbe) {
  test::TempDir dir;
  write_list(dir.path(), {0.0, 1.0 / 30, 2.0 / 30});
  FrameGraph graph;
  graph.emplace<TimestampSource>(std::vector<double>{0.0, 0.4 / 30, 1.0 / 30, 2.0 / 30});
  std::ostringstream warnings;
  graph.emplace<ProbeStreamStage>(open_probe_stream(dir.path(), {}), ProbeMatchOptions{}, warnings);
  auto& recorder = graph.emplace<ProbeRecorder>();
  graph.compile();
  while (graph.run_frame()) {
  }
  EXPECT_EQ(recorder.markers, (std::vector<float>{1.f, 1.f, 2.f, 3.f}));
}

}  // namespace
}  // namespace relight::lights
