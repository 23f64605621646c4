#include "relight/synth/tag36h11.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>

namespace relight::synth {
namespace {

TEST(Tag36h11, BitLayoutCoversEveryDataCellOnce) {
  std::set<std::pair<int, int>> cells;
  for (std::size_t i = 0; i < kTag36h11BitX.size(); ++i) {
    EXPECT_GE(kTag36h11BitX[i], 1);
    EXPECT_LE(kTag36h11BitX[i], 6);
    EXPECT_GE(kTag36h11BitY[i], 1);
    EXPECT_LE(kTag36h11BitY[i], 6);
    cells.insert({kTag36h11BitX[i], kTag36h11BitY[i]});
  }
  EXPECT_EQ(cells.size(), 36u);
}

// AprilTag 2 listed tag36h11 id 0 as 0xd5d628584 with the bits in row-major order (most
// significant bit top-left). AprilTag 3 reordered the bits (0xd7e00984b) but kept the tags, so
// both must give the same picture: an independent check of the code and of the layout tables.
TEST(Tag36h11, Id0MatchesTheRowMajorCodeOfAprilTag2) {
  constexpr std::uint64_t row_major = 0xd5d628584ULL;
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 6; ++col) {
      const bool expected = ((row_major >> (35 - (row * 6 + col))) & 1u) != 0;
      EXPECT_EQ(tag36h11_cell_is_white(kTag36h11Codes[0], row + 2, col + 2), expected) << row << "," << col;
    }
  }
}

TEST(Tag36h11, WhiteMarginAndBlackBorder) {
  for (int i = 0; i < 10; ++i) {
    EXPECT_TRUE(tag36h11_cell_is_white(kTag36h11Codes[0], 0, i));
    EXPECT_TRUE(tag36h11_cell_is_white(kTag36h11Codes[0], i, 9));
  }
  for (int i = 1; i < 9; ++i) {
    EXPECT_FALSE(tag36h11_cell_is_white(kTag36h11Codes[0], 1, i));
    EXPECT_FALSE(tag36h11_cell_is_white(kTag36h11Codes[0], i, 8));
  }
}

TEST(Tag36h11, DecodeInvertsTheLayout) {
  for (std::uint64_t code : kTag36h11Codes) {
    const auto decoded =
        tag36h11_decode([&](int row, int col) { return tag36h11_cell_is_white(code, row + 2, col + 2); });
    EXPECT_EQ(decoded, code);
  }
}

}  // namespace
}  // namespace relight::synth
