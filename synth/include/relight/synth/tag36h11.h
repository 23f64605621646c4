#pragma once
// The AprilTag tag36h11 family as AprilTag 3 lays it out: a 10x10 grid of cells (white outer
// ring, black 8x8 border, 6x6 data bits). Bit i of a code (i = 0 is the most significant of the
// 36) sits at data cell kTag36h11BitX[i], kTag36h11BitY[i] (column, row counted from the black
// border, 1..6); a set bit is white. Codes and layout: AprilRobotics/apriltag, tag36h11.c.
#include <array>
#include <cstdint>

namespace relight::synth {

/// The first codes of tag36h11 (ids 0..3).
inline constexpr std::array<std::uint64_t, 4> kTag36h11Codes = {0xd7e00984bULL, 0xdda664ca7ULL, 0xdc4a1c821ULL,
                                                                0xe17b470e9ULL};

inline constexpr std::array<int, 36> kTag36h11BitX = {1, 2, 3, 4, 5, 2, 3, 4, 3, 6, 6, 6, 6, 6, 5, 5, 5, 4,
                                                      6, 5, 4, 3, 2, 5, 4, 3, 4, 1, 1, 1, 1, 1, 2, 2, 2, 3};
inline constexpr std::array<int, 36> kTag36h11BitY = {1, 1, 1, 1, 1, 2, 2, 2, 3, 1, 2, 3, 4, 5, 2, 3, 4, 3,
                                                      6, 6, 6, 6, 6, 5, 5, 5, 4, 6, 5, 4, 3, 2, 5, 4, 3, 4};

/// Whether cell (row, col) of the full 10x10 tag image is white (row 0 = top, col 0 = left).
[[nodiscard]] bool tag36h11_cell_is_white(std::uint64_t code, int row, int col);

/// Reads a code back from the 6x6 data cells (the inverse of the layout above), so tests can
/// decode a rendered tag.
template <class IsWhite>
[[nodiscard]] std::uint64_t tag36h11_decode(IsWhite&& data_cell_is_white /* (row 0..5, col 0..5) */) {
  std::uint64_t code = 0;
  for (std::size_t i = 0; i < kTag36h11BitX.size(); ++i) {
    code = (code << 1) | (data_cell_is_white(kTag36h11BitY[i] - 1, kTag36h11BitX[i] - 1) ? 1u : 0u);
  }
  return code;
}

}  // namespace relight::synth
