#pragma once
// `--frames A:B` ranges: frames A (inclusive) to B (exclusive), counted from 0 in the source.
// "A:" runs to the end, ":B" starts at 0, "N" means the first N frames (0:N).
#include <cstddef>
#include <optional>
#include <string_view>

namespace relight::app {

struct FrameRange {
  std::size_t first = 0;
  std::optional<std::size_t> last;  ///< exclusive; nullopt = to the end
};

/// Throws relight::Error with the offending text when it is not a valid range.
FrameRange parse_frame_range(std::string_view text);

}  // namespace relight::app
