#include "relight/capture/source_stage.h"

#include <gtest/gtest.h>

#include "relight/capture/tum_sequence.h"

namespace relight {
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
}  // namespace relight
