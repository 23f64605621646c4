#include "report.h"

#include <gtest/gtest.h>

#include <regex>

#include "constant_stage.h"
#include "html_report.h"
#include "relight/core/buffers.h"
#include "relight/lights/buffers.h"
#include "report_collector_stage.h"

namespace relight::app {
namespace {

TEST(Report, SummaryStatistics) {
  const MsSummary s = summarize({5, 1, 3, 2, 4});
  EXPECT_DOUBLE_EQ(s.median, 3);
  EXPECT_DOUBLE_EQ(s.mean, 3);
  EXPECT_DOUBLE_EQ(s.max, 5);
  EXPECT_DOUBLE_EQ(s.p95, 5);
  EXPECT_DOUBLE_EQ(summarize({1, 2, 3, 4}).median, 2.5);
  std::vector<double> hundred;
  for (int i = 1; i <= 100; ++i) hundred.push_back(i);
  EXPECT_DOUBLE_EQ(summarize(hundred).p95, 95);
  EXPECT_DOUBLE_EQ(summarize({}).median, 0);
}

TEST(HtmlReport, Base64AndEscapingFollowTheirStandards) {
  // RFC 4648 section 10 test vectors.
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\xd8\xff", 3)), "/9j/");
  EXPECT_EQ(html_escape("a<b>&\"c\""), "a&lt;b&gt;&amp;&quot;c&quot;");
}

// A stage writing a frame-numbered grey picture, ending the stream after `frames` frames.
class CountingPictureStage final : public Stage {
 public:
  explicit CountingPictureStage(std::int64_t frames) : frames_(frames) {}
  [[nodiscard]] std::string name() const override { return "counting"; }
  void declare(StageBuilder& builder) override { picture_ = builder.write<ColorImage>("color"); }
  void run(StageContext& context) override {
    if (context.frame_index() >= frames_) return context.end_of_stream();
    const auto grey = static_cast<std::uint8_t>(20 * context.frame_index());
    context.get(picture_) = ColorImage(64, 32, Rgb8{grey, grey, grey});
  }

 private:
  std::int64_t frames_;
  Write<ColorImage> picture_;
};

lights::Light directional_light(const Eigen::Vector3d& direction, const Eigen::Vector3d& power) {
  lights::Light light;
  light.direction = direction;
  light.power = power;
  return light;
}

std::vector<std::int64_t> sheet_frames(const ReportContent& content) {
  std::vector<std::int64_t> frames;
  for (const auto& row : content.contact_sheet) frames.push_back(row.frame);
  return frames;
}

ReportContent collect(std::int64_t frames, std::int64_t announced_total) {
  FrameGraph graph;
  graph.emplace<CountingPictureStage>(frames);
  lights::LightSet lights;
  lights.lights.push_back(directional_light(Eigen::Vector3d::UnitZ(), {1, 0.5, 0.25}));
  graph.emplace<ConstantStage<lights::LightSet>>(lights::kLights, lights);
  auto stage = std::make_unique<ReportCollectorStage>(announced_total, 4, 16);
  stage->add_picture(kColor);  // before the stage joins the graph
  stage->collect_lights(lights::kLights);
  const ReportCollectorStage& collector = *stage;
  graph.add(std::move(stage));
  graph.compile();
  while (graph.run_frame()) {
  }
  return collector.content();
}

TEST(HtmlReport, CollectorPicksFramesEvenlyOrFirstAndLatest) {
  const ReportContent known = collect(10, 10);
  EXPECT_EQ(sheet_frames(known), (std::vector<std::int64_t>{0, 3, 6, 9}));
  ASSERT_EQ(known.contact_sheet[1].pictures.size(), 1u);
  const Thumbnail& thumbnail = known.contact_sheet[1].pictures[0];
  EXPECT_EQ(thumbnail.height, 16);
  EXPECT_EQ(thumbnail.width, 32);  // aspect ratio kept
  EXPECT_EQ(thumbnail.jpeg.substr(0, 3), std::string("\xff\xd8\xff", 3));
  ASSERT_TRUE(known.lights);
  EXPECT_EQ(known.lights->lights.size(), 1u);

  EXPECT_EQ(sheet_frames(collect(40, 0)), (std::vector<std::int64_t>{0, 30}));  // live: first and latest
  EXPECT_EQ(sheet_frames(collect(2, 2)), (std::vector<std::int64_t>{0, 1}));   // fewer frames than rows
}

nlohmann::ordered_json two_stage_timing() {
  nlohmann::ordered_json timing;
  timing["sequence"] = "folder <with> & odd \"name\"";
  timing["frames"] = 3;
  timing["fps"] = 2.5;
  timing["execution_order"] = {"source", "dir"};
  timing["stages"] = nlohmann::ordered_json::array();
  for (const auto& [stage, ms] : {std::pair{"source", 10.0}, std::pair{"dir", 300.0}}) {
    nlohmann::ordered_json entry;
    entry["stage"] = stage;
    entry["backend"] = "CPU";
    entry["frames"] = 3;
    entry["median_ms"] = ms;
    entry["wall_ms"] = {ms * 3, ms, ms};
    timing["stages"].push_back(entry);
  }
  return timing;
}

TEST(HtmlReport, PageIsSelfContainedAndShowsEverySection) {
  ReportContent content;
  content.contact_sheet.push_back({0, {{"composite", std::string("\xff\xd8\xff\xe0", 4), 8, 6}}});
  content.materials = std::vector<brdf::MaterialParams>{{{{0.5f, 0.25f, 0.125f}, 0.3f, 40.f}, 1234, 0.01f}};
  content.lights = lights::LightSet{{directional_light({0, 0.6, 0.8}, {2, 2, 2})}};
  nlohmann::ordered_json timing = two_stage_timing();
  timing["dir_steps"] = {
      {"frames", 3}, {"shading_on", "cpu"}, {"median_ms", {{"gbuffer", 31.5}, {"shadow_maps", 64.25}}}};
  const std::string html = html_report("title", timing, content, "digraph {}", std::nullopt);

  // No resource leaves the page: the only URL is the SVG namespace name.
  const std::regex external(R"((src|href)\s*=\s*["']?(https?:|//))");
  EXPECT_FALSE(std::regex_search(html, external));
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_NE(html.find("folder &lt;with&gt; &amp; odd &quot;name&quot;"), std::string::npos);
  EXPECT_NE(html.find("src=\"data:image/jpeg;base64,/9j/4A==\""), std::string::npos);
  // Timing table: the median shares, and the plot with one area per stage.
  EXPECT_NE(html.find("97 %"), std::string::npos);  // dir: 300 / 310
  // Where the dir stage's time went, inline in the summary.
  EXPECT_NE(html.find("median_ms = gbuffer 31.5, shadow_maps 64.2"), std::string::npos);
  std::size_t polygons = 0;
  for (auto at = html.find("<polygon"); at != std::string::npos; at = html.find("<polygon", at + 1)) ++polygons;
  EXPECT_EQ(polygons, 2u);
  EXPECT_NE(html.find("Frame 0 (930.0 ms"), std::string::npos);  // the set-up frame is clipped and says so
  // Materials: the swatch is k_d in sRGB (0.5 -> 0xbc, 0.25 -> 0x89, 0.125 -> 0x63).
  EXPECT_NE(html.find("background:#bc8963"), std::string::npos);
  EXPECT_NE(html.find("1234"), std::string::npos);
  // Lights, and the graph listed when Graphviz did not draw it.
  EXPECT_NE(html.find("directional"), std::string::npos);
  EXPECT_NE(html.find("Graphviz (dot) is not installed"), std::string::npos);
  EXPECT_NE(html.find("<li>dir"), std::string::npos);
  const std::string drawn = html_report("title", two_stage_timing(), content, "digraph {}", "<svg>drawn</svg>");
  EXPECT_NE(drawn.find("<svg>drawn</svg>"), std::string::npos);
  EXPECT_EQ(drawn.find("not installed"), std::string::npos);
}

}  // namespace
}  // namespace relight::app
