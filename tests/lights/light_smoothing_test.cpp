// Temporal stability: the extraction + smoothing stages in a frame graph over probe sequences.
#include "relight/lights/light_smoothing.h"

#include <gtest/gtest.h>

#include <random>

#include "probes.h"
#include "relight/core/frame_graph.h"
#include "relight/lights/light_stages.h"

namespace relight::lights {
namespace {

using test::angle_between;
using test::radians;

// Source stage: writes the next probe of a fixed list into "probe".
class ProbeSequenceStage final : public Stage {
 public:
  explicit ProbeSequenceStage(std::vector<RadianceImage> frames) : frames_(std::move(frames)) {}
  std::string name() const override { return "probe_source"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override { probe_ = builder.write<RadianceImage>("probe"); }
  void run(StageContext& context) override {
    const auto i = static_cast<std::size_t>(context.frame_index());
    if (i >= frames_.size()) return context.end_of_stream();
    context.get(probe_) = frames_[i];
  }

 private:
  std::vector<RadianceImage> frames_;
  Write<RadianceImage> probe_;
};

struct SequenceRun {
  std::vector<LightSet> raw;
  std::vector<LightSet> smoothed;
};

SequenceRun run_sequence(std::vector<RadianceImage> frames, const ProbeCalibration& calibration) {
  FrameGraph graph;
  graph.emplace<ProbeSequenceStage>(std::move(frames));
  graph.emplace<LightExtractionStage>(LightExtractionOptions{LightMethod::Importance, 64, 0, calibration});
  graph.emplace<LightSmoothingStage>();
  graph.keep("lights");
  graph.keep("lights_raw");
  graph.compile();
  SequenceRun run;
  while (graph.run_frame()) {
    run.raw.push_back(*graph.find<LightSet>("lights_raw"));
    run.smoothed.push_back(*graph.find<LightSet>("lights"));
  }
  return run;
}

// The brightest cluster within 3 degrees of `direction`, or null.
std::optional<Light> cluster_near(const LightSet& set, const Eigen::Vector3d& direction) {
  for (const Light& cluster : cluster_lights(set, radians(5)).lights) {
    if (angle_between(cluster.direction, direction) < radians(3)) return cluster;
  }
  return std::nullopt;
}

const test::SynthProbe& probe_without_main_light() {
  static const test::SynthProbe probe = test::render_synth_probe([](synth::Scene& scene) {
    scene.lights.erase(scene.lights.begin());
  });
  return probe;
}

ProbeCalibration calibration_of(const test::SynthProbe& s) { return s.geometry.calibration(); }

bool same(const LightSet& a, const LightSet& b) {
  if (a.lights.size() != b.lights.size()) return false;
  for (std::size_t i = 0; i < a.lights.size(); ++i) {
    if (a.lights[i].direction != b.lights[i].direction || a.lights[i].power != b.lights[i].power) return false;
  }
  return true;
}

TEST(LightSmoothing, StaticProbeGivesTheSameLightSetEveryFrame) {
  const test::SynthProbe& s = test::default_synth_probe();
  const SequenceRun run = run_sequence({s.image, s.image, s.image, s.image}, calibration_of(s));
  ASSERT_EQ(run.smoothed.size(), 4u);
  for (std::size_t f = 1; f < 4; ++f) EXPECT_TRUE(same(run.smoothed[f], run.smoothed[0])) << "frame " << f;
}

TEST(LightSmoothing, LightSwitchedOnAppearsAndSwitchedOffDisappearsWithinTwoFrames) {
  const test::SynthProbe& on = test::default_synth_probe();
  const test::SynthProbe& off = probe_without_main_light();
  const synth::PointLight& main_light = on.scene.lights[0];
  const Eigen::Vector3d direction = test::light_direction(on, main_light);
  const double true_power = luminance(test::light_irradiance(on, main_light));

  const SequenceRun switch_on = run_sequence({off.image, off.image, on.image, on.image, on.image}, calibration_of(on));
  EXPECT_FALSE(cluster_near(switch_on.smoothed[1], direction));
  bool appeared = false;
  for (std::size_t f = 2; f <= 3; ++f) {  // the switch frame or the one after
    const auto cluster = cluster_near(switch_on.smoothed[f], direction);
    appeared = appeared || (cluster && std::abs(luminance(cluster->power) / true_power - 1.0) < 0.15);
  }
  EXPECT_TRUE(appeared);

  const SequenceRun switch_off = run_sequence({on.image, on.image, off.image, off.image, off.image}, calibration_of(on));
  EXPECT_TRUE(cluster_near(switch_off.smoothed[1], direction));
  const auto left = cluster_near(switch_off.smoothed[3], direction);
  EXPECT_TRUE(!left || luminance(left->power) < 0.05 * true_power);
}

TEST(LightSmoothing, SensorNoiseFlickersLessAfterSmoothing) {
  const test::SynthProbe& s = test::default_synth_probe();
  std::mt19937 random(3);
  std::normal_distribution<float> noise(1.f, 0.05f);  // 5 % multiplicative noise per pixel
  std::vector<RadianceImage> frames;
  for (int f = 0; f < 8; ++f) {
    RadianceImage frame = s.image;
    for (Float3& p : frame.pixels()) p = noise(random) * p;
    frames.push_back(std::move(frame));
  }
  const SequenceRun run = run_sequence(std::move(frames), calibration_of(s));
  auto flicker = [](const std::vector<LightSet>& sets) {
    double change = 0.0;
    for (std::size_t f = 1; f < sets.size(); ++f) {
      for (std::size_t i = 0; i < sets[f].lights.size(); ++i) {
        change += std::abs(luminance(sets[f].lights[i].power) - luminance(sets[f - 1].lights[i].power));
      }
    }
    return change;
  };
  EXPECT_LT(flicker(run.smoothed), 0.7 * flicker(run.raw));
}

}  // namespace
}  // namespace relight::lights
