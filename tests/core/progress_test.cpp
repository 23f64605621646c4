#include "relight/core/progress.h"

#include <gtest/gtest.h>

namespace relight {
namespace {

TEST(ProgressBar, ShowsCountFpsAndEta) {
  const std::string line = ProgressBar::format("synth", 10, 30, 2.0, 10);
  EXPECT_EQ(line, "synth [###.......] 10/30 frames  5.0 fps  ETA 4s");
}

TEST(ProgressBar, UnknownTotalHasNoEta) {
  const std::string line = ProgressBar::format("live", 90, 0, 3.0);
  EXPECT_EQ(line, "live 90 frames  30.0 fps");
}

}  // namespace
}  // namespace relight
