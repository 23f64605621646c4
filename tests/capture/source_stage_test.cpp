#include "relight/capture/source_stage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <thread>

#include "relight/capture/looping_source.h"
#include "relight/capture/prefetch_source.h"
#include "relight/capture/range_source.h"
#include "relight/capture/tum_sequence.h"
#include "relight/core/error.h"

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

/// CountingSource that throws instead of returning frame `bad` (once), and records how many
/// frames were asked for and whether any read ran on the caller's thread.
class RecordingSource final : public FrameSource {
 public:
  RecordingSource(int count, int bad) : counting_(count), bad_(bad) {}
  std::optional<RgbdFrame> next() override {
    ++reads_;
    if (std::this_thread::get_id() == caller_) on_caller_thread_ = true;
    auto frame = counting_.next();
    if (frame && frame->info.index == bad_) throw Error("frame " + std::to_string(bad_) + " is unreadable");
    return frame;
  }
  std::int64_t size_hint() const override { return counting_.size_hint(); }
  std::string describe() const override { return "recording"; }
  [[nodiscard]] int reads() const { return reads_; }
  [[nodiscard]] bool on_caller_thread() const { return on_caller_thread_; }

 private:
  CountingSource counting_;
  int bad_;
  std::thread::id caller_ = std::this_thread::get_id();
  std::atomic<int> reads_ = 0;
  std::atomic<bool> on_caller_thread_ = false;
};

TEST(PrefetchSource, ReadsOneFrameAheadOnAnotherThreadAndKeepsOrderAndErrors) {
  auto owned = std::make_unique<RecordingSource>(5, 2);
  const RecordingSource& inner = *owned;
  PrefetchSource source(std::move(owned));
  EXPECT_EQ(source.size_hint(), 5);  // waits for the first read
  EXPECT_EQ(inner.reads(), 1) << "the first frame is read at once";
  auto frame = source.next();
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->info.index, 0);
  EXPECT_EQ(source.describe(), "recording");
  EXPECT_EQ(inner.reads(), 2) << "frame 1 was read while frame 0 was in use";
  EXPECT_EQ(source.next()->info.index, 1);
  EXPECT_THROW((void)source.next(), Error) << "frame 2's error, in its place";
  EXPECT_EQ(source.next()->info.index, 3) << "the caller may go on after an error";
  EXPECT_EQ(source.next()->info.index, 4);
  EXPECT_FALSE(source.next());
  EXPECT_FALSE(source.next()) << "still the end";
  EXPECT_FALSE(inner.on_caller_thread()) << "every read runs on the worker thread";
}

TEST(PrefetchSource, FeedsTheGraphTheSameFramesAsTheSourceItself) {
  const auto folder = std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy";
  TumSource direct(TumSequence::open(folder));
  PrefetchSource prefetched(std::make_unique<TumSource>(TumSequence::open(folder)));
  int frames = 0;
  while (auto expected = direct.next()) {
    const auto frame = prefetched.next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->info.index, expected->info.index);
    EXPECT_EQ(frame->info.timestamp, expected->info.timestamp);
    EXPECT_TRUE(std::ranges::equal(frame->color.pixels(), expected->color.pixels()));
    EXPECT_TRUE(std::ranges::equal(frame->depth.pixels(), expected->depth.pixels()));
    ++frames;
  }
  EXPECT_FALSE(prefetched.next());
  EXPECT_EQ(frames, 4);
}

}  // namespace
}  // namespace relight::capture
