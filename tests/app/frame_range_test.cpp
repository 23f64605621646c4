#include "frame_range.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"

namespace relight::app {
namespace {

TEST(FrameRange, Forms) {
  EXPECT_EQ(parse_frame_range("2:5").first, 2u);
  EXPECT_EQ(*parse_frame_range("2:5").last, 5u);
  EXPECT_FALSE(parse_frame_range("3:").last.has_value());
  EXPECT_EQ(parse_frame_range(":4").first, 0u);
  EXPECT_EQ(*parse_frame_range("10").last, 10u);
}

TEST(FrameRange, Rejects) {
  for (const char* bad : {"", "5:5", "6:2", "a:3", "1:b", "-1:3", "0"}) {
    EXPECT_THROW((void)parse_frame_range(bad), Error) << bad;
  }
}

}  // namespace
}  // namespace relight::app
