// The tone-mapping operators (tone_map.h) and Reinhard's adapted key (adaptive_tone_map.h,
// tone_map_stage.h): the exposure clamp is unchanged, Reinhard's curve rolls highlights off and
// keeps hue, eq. 1 is the log average of the lit pixels, and through the graph the key follows a
// light switched off with the closed-form exponential adaptation; the mapping stages apply the
// graph's operator of each frame.
#include <gtest/gtest.h>

#include <cmath>

#include "relight/colormap/adaptive_tone_map.h"
#include "relight/colormap/colormap_stages.h"
#include "relight/colormap/tone_map_stage.h"

namespace relight::colormap {
namespace {

ToneMap reinhard(float scale, float white) {
  return {.op = ToneOperator::Reinhard, .exposure = scale, .inverse_white_squared = 1.f / (white * white)};
}

TEST(ToneMap, ExposureIsTheClampedScale) {
  const ToneMap tm{.exposure = 2.f};
  for (const float v : {0.f, 0.1f, 0.3f, 0.49f, 0.6f, 7.f}) {
    const Float3 mapped = tone_map(Float3{v, 0.5f * v, 0.25f * v}, tm);
    EXPECT_EQ(mapped.x, std::clamp(2.f * v, 0.f, 1.f));  // exact: the factor is 1
    EXPECT_EQ(mapped.y, std::clamp(v, 0.f, 1.f));
    EXPECT_EQ(mapped.z, std::clamp(0.5f * v, 0.f, 1.f));
  }
  EXPECT_EQ(tone_map(Float3{-1.f, 0.f, 0.f}, tm).x, 0.f);
}

TEST(ToneMap, ReinhardRollsHighlightsOffAndKeepsHue) {
  const ToneMap tm = reinhard(1.f, 8.f);
  float previous = 0.f;
  for (float y = 0.05f; y < 8.f; y *= 1.25f) {  // grey: luminance y
    const float mapped = tone_map(Float3{y, y, y}, tm).x;
    EXPECT_GT(mapped, previous) << y;  // strictly increasing: no plateau where the clamp would clip
    EXPECT_LT(mapped, 1.f) << y;       // below the white nothing reaches 1
    // Eq. 4 in closed form.
    EXPECT_NEAR(mapped, y * (1.f + y / 64.f) / (1.f + y), 1e-6f) << y;
    previous = mapped;
  }
  EXPECT_NEAR(tone_map(Float3{8.f, 8.f, 8.f}, tm).x, 1.f, 1e-6f);  // the white maps to 1
  // Small values: the curve starts as the exposure's line.
  EXPECT_NEAR(tone_map(Float3{1e-3f, 1e-3f, 1e-3f}, tm).x, 1e-3f, 2e-6f);
  // A coloured highlight keeps its channel ratios where nothing clips.
  const Float3 orange = tone_map(Float3{2.f, 1.f, 0.4f}, tm);
  EXPECT_NEAR(orange.y / orange.x, 0.5f, 1e-5f);
  EXPECT_NEAR(orange.z / orange.x, 0.2f, 1e-5f);
  // A saturated highlight just below the white clips no channel (the curve runs on the largest).
  const Float3 red = tone_map(Float3{7.9f, 0.6f, 0.3f}, tm);
  EXPECT_LT(red.x, 1.f);
  EXPECT_GT(red.x, 0.99f);
  EXPECT_NEAR(red.y / red.x, 0.6f / 7.9f, 1e-5f);
  // The exposure clamp of the same colour clips red and green to 1 (hue lost).
  const Float3 clipped = tone_map(Float3{2.f, 1.f, 0.4f}, ToneMap{});
  EXPECT_EQ(clipped.x, clipped.y);
}

RadianceImage grey_image(int width, int height, float value) {
  return RadianceImage(width, height, Float3{value, value, value});
}

TEST(SceneLuminance, IsTheLogAverageOfTheLitPixels) {
  // Half the lit pixels at Y = 0.1, half at 0.4, a third of the image without light.
  RadianceImage image(60, 30);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 60; ++x) {
      const float v = x < 20 ? 0.f : (x < 40 ? 0.1f : 0.4f);
      image(y, x) = {v, v, v};
    }
  image(0, 0) = {NAN, 0.f, 0.f};  // not a number: left out
  const SceneLuminance all = scene_luminance(image, 1);
  EXPECT_EQ(all.pixels, 40 * 30);
  EXPECT_NEAR(all.log_average, 0.2, 1e-5);  // sqrt(0.1 * 0.4)
  EXPECT_NEAR(all.max, 0.4, 1e-6);
  EXPECT_NEAR(scene_luminance(image, 2).log_average, 0.2, 1e-5);
  EXPECT_EQ(scene_luminance(RadianceImage(8, 8), 2).pixels, 0);
}

TEST(AdaptiveToneMap, MapsTheLogAverageToTheKeyAndTheBrightestPixelToWhite) {
  const ToneMapOptions options{.op = ToneOperator::Reinhard, .key = 0.18f};
  SceneLuminance scene;
  scene.log_average = 0.5;
  scene.max = 20.0;
  scene.pixels = 100;
  const ToneMap tm = adapt_tone_map(options, scene, nullptr, 1.0 / 30.0);
  EXPECT_NEAR(tm.exposure, 0.36f, 1e-6f);
  EXPECT_NEAR(tone_map(Float3{20.f, 20.f, 20.f}, tm).x, 1.f, 1e-5f);
  EXPECT_LT(tone_map(Float3{19.f, 19.f, 19.f}, tm).x, 1.f);
  // A dark scene (max below what the key scales to 1) gets no expansion: L_white = 1.
  scene.max = 1.0;
  EXPECT_FLOAT_EQ(adapt_tone_map(options, scene, nullptr, 0.0).inverse_white_squared, 1.f);
  // Exposure ignores the scene.
  const ToneMap fixed = adapt_tone_map({.exposure = 3.f}, scene, nullptr, 0.0);
  EXPECT_EQ(fixed.op, ToneOperator::Exposure);
  EXPECT_EQ(fixed.exposure, 3.f);
}

// Writes "frame" (30 fps timestamps) and "L_rv" (grey, bright until `switch_frame`, then dark).
class SwitchedLight final : public Stage {
 public:
  SwitchedLight(int switch_frame, float bright, float dark) : switch_(switch_frame), bright_(bright), dark_(dark) {}
  [[nodiscard]] std::string name() const override { return "switched_light"; }
  void declare(StageBuilder& builder) override {
    frame_ = builder.write(kFrame);
    real_virtual_ = builder.write(kRealVirtualRadiance);
  }
  void run(StageContext& context) override {
    context.get(frame_).index = index_;
    context.get(frame_).timestamp = 100.0 + index_ / 30.0;
    context.get(real_virtual_) = grey_image(32, 24, index_ < switch_ ? bright_ : dark_);
    ++index_;
  }

 private:
  int switch_, index_ = 0;
  float bright_, dark_;
  Write<FrameInfo> frame_;
  Write<RadianceImage> real_virtual_;
};

TEST(ToneMapStage, KeyFollowsALightSwitchedOffWithinTheAdaptationTime) {
  constexpr double kTau = 0.5;
  constexpr int kSwitch = 30;  // one second bright, then the light goes off (10x darker)
  FrameGraph graph;
  graph.emplace<SwitchedLight>(kSwitch, 1.f, 0.1f);
  auto& stage = graph.emplace<ToneMapStage>(ToneMapOptions{.op = ToneOperator::Reinhard, .adaptation_s = kTau});
  graph.keep(kToneMap);
  graph.compile();
  for (int frame = 0; frame < 30 * 4; ++frame) {
    ASSERT_TRUE(graph.run_frame());
    const double log_average = stage.last().log_average_luminance;
    if (frame < kSwitch) {
      EXPECT_NEAR(log_average, 1.0, 1e-5) << frame;  // a steady scene: adapted from the first frame
      continue;
    }
    // Closed form: log L(t) = log 0.1 + log 10 * exp(-t / tau), t since the switch.
    const double t = (frame - kSwitch + 1) / 30.0;
    const double expected = 0.1 * std::exp(std::log(10.0) * std::exp(-t / kTau));
    EXPECT_NEAR(log_average, expected, 1e-3 * expected) << frame;
    if (t <= kTau / 2) {
      EXPECT_GT(log_average, 0.2) << "a change of a few frames must not pump the picture: " << frame;
    }
    if (t >= 4 * kTau) {
      EXPECT_NEAR(log_average, 0.1, 0.005) << "adapted within 4 tau: " << frame;
    }
  }
  // The key maps the dark scene's average to 0.18 again.
  EXPECT_NEAR(tone_map(Float3{0.1f, 0.1f, 0.1f}, stage.last()).x, 0.18f * (1.f + 0.18f / 1.f) / 1.18f, 2e-3f);
  const ToneMap* written = graph.find<ToneMap>(kToneMap.name());
  ASSERT_NE(written, nullptr);
  EXPECT_EQ(written->exposure, stage.last().exposure);
}

// Writes "frame", "L_rv" (grey 4 with a highlight of 40 at pixel (5, 5)), "L_r" (grey 4) and "color".
class Highlight final : public Stage {
 public:
  [[nodiscard]] std::string name() const override { return "highlight"; }
  void declare(StageBuilder& builder) override {
    frame_ = builder.write(kFrame);
    real_virtual_ = builder.write(kRealVirtualRadiance);
    real_ = builder.write(kRealRadiance);
    color_ = builder.write(kColor);
  }
  void run(StageContext& context) override {
    context.get(real_) = grey_image(32, 24, 4.f);
    context.get(real_virtual_) = grey_image(32, 24, 4.f);
    context.get(real_virtual_)(5, 5) = {40.f, 40.f, 40.f};
    context.get(color_) = ColorImage(32, 24, Rgb8{128, 128, 128});
  }

 private:
  Write<FrameInfo> frame_;
  Write<RadianceImage> real_virtual_, real_;
  Write<ColorImage> color_;
};

TEST(ToneMapStage, MappingStagesApplyTheGraphsOperatorOfEachFrame) {
  FrameGraph graph;
  graph.emplace<Highlight>();
  auto& stage = graph.emplace<ToneMapStage>(ToneMapOptions{.op = ToneOperator::Reinhard});
  ColorMapBuffers buffers;
  buffers.tone_map = kToneMap;
  graph.add(make_color_map_stage(ColorMapMethod::None, Backend::Cpu, nullptr, {}, buffers));
  graph.keep(kDeltaRadiance);
  graph.keep(kColorMapping);
  graph.compile();
  ASSERT_TRUE(graph.run_frame());
  const ToneMap& tm = stage.last();
  ASSERT_EQ(tm.op, ToneOperator::Reinhard);
  EXPECT_GT(tm.inverse_white_squared, 0.f);
  const ColorMapping* mapping = graph.find<ColorMapping>(kColorMapping.name());
  ASSERT_NE(mapping, nullptr);
  EXPECT_EQ(mapping->tone_map.exposure, tm.exposure);
  EXPECT_EQ(mapping->tone_map.op, ToneOperator::Reinhard);
  const RadianceImage* delta = graph.find<RadianceImage>(kDeltaRadiance.name());
  ASSERT_NE(delta, nullptr);
  const float highlight = tone_map(Float3{40.f, 40.f, 40.f}, tm).x, grey = tone_map(Float3{4.f, 4.f, 4.f}, tm).x;
  EXPECT_NEAR((*delta)(5, 5).x, highlight - grey, 1e-6f);
  EXPECT_NEAR(highlight, 1.f, 1e-5f);  // the brightest pixel is the white
  EXPECT_EQ((*delta)(0, 0).x, 0.f);
}

}  // namespace
}  // namespace relight::colormap
