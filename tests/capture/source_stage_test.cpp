#include "relight/capture/source_stage.h"

#include <gtest/gtest.h>

#include "relight/capture/looping_source.h"
#include "relight/capture/range_source.h"
#include "relight/capture/tum_sequence.h"

namespace relight::capture {
namespace {

TEST(SourceStage, FeedsTheGraphUntilTheSourceEnds) {
  const auto folder = std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy";
  FrameGraph graph;
  graph.emplace<SourceStage>(std::make_unique<TumSource>(TumSequence::open(folder)));
  int frames = 0;
  while (graph.run_frame()) {
    const FrameInfo* info = graph.find<FrameInfo>("frame");
    ASSERT_NE(info, nullptr);
    EXPECT_EQ(info->index, frames);
    EXPECT_EQ(graph.find<DepthMap>("depth")->width(), 640);
    EXPECT_EQ(graph.find<ColorImage>("color")->height(), 480);
    ++frames;
  }
  EXPECT_EQ(frames, 4);
}

}  // namespace
}  // namespace relight::capture

namespace relight::capture {
namespace {

/// `count` empty frames at 30 fps from t = 10 s.
class CountingSource final : public FrameSource {
 public:
  explicit CountingSource(int count) : count_(count) {}
  std::optional<RgbdFrame> next() override {
    if (next_ >= count_) return std::nullopt;
    RgbdFrame frame;
    frame.info.index = next_;
    frame.info.timestamp = 10.0 + next_++ / 30.0;
    return frame;
  }
  std::int64_t size_hint() const override { return count_; }
  std::string describe() const override { return "counting"; }

 private:
  int count_;
  int next_ = 0;
};

TEST(RangeSource, SkipsToTheFirstFrameStopsBeforeTheLastAndCountsFromZero) {
  RangeSource range(std::make_unique<CountingSource>(10), 3, 6);
  EXPECT_EQ(range.size_hint(), 3);
  std::vector<double> timestamps;
  while (auto frame = range.next()) {
    EXPECT_EQ(frame->info.index, static_cast<std::int64_t>(timestamps.size()));
    timestamps.push_back(frame->info.timestamp);
  }
  ASSERT_EQ(timestamps.size(), 3u);
  EXPECT_NEAR(timestamps.front(), 10.0 + 3 / 30.0, 1e-12);
  EXPECT_EQ(RangeSource(std::make_unique<CountingSource>(4), 2, std::nullopt).size_hint(), 2);
}

TEST(LoopingSource, PlaysAgainWithIndicesAndTimestampsThatKeepGrowing) {
  LoopingSource looping([] { return std::make_unique<CountingSource>(3); }, 3);
  EXPECT_EQ(looping.size_hint(), 9);
  std::int64_t frames = 0;
  double last = 0.0;
  while (auto frame = looping.next()) {
    EXPECT_EQ(frame->info.index, frames++);
    EXPECT_GT(frame->info.timestamp, last);
    if (frames > 1) {
      EXPECT_NEAR(frame->info.timestamp - last, 1.0 / 30.0, 1e-9);  // one period, also between passes
    }
    last = frame->info.timestamp;
  }
  EXPECT_EQ(frames, 9);
}

}  // namespace
}  // namespace relight::capture
