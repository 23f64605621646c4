#include "frame_range.h"

#include <charconv>
#include <string>

#include "relight/core/error.h"

namespace relight::app {

namespace {
std::optional<std::size_t> parse_count(std::string_view text, std::string_view whole) {
  if (text.empty()) return std::nullopt;
  std::size_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) {
    throw Error("--frames '" + std::string(whole) + "': '" + std::string(text) + "' is not a frame number");
  }
  return value;
}
}  // namespace

FrameRange parse_frame_range(std::string_view text) {
  FrameRange range;
  const auto colon = text.find(':');
  if (colon == std::string_view::npos) {
    range.last = parse_count(text, text);
    if (!range.last) throw Error("--frames is empty");
  } else {
    range.first = parse_count(text.substr(0, colon), text).value_or(0);
    range.last = parse_count(text.substr(colon + 1), text);
  }
  if (range.last && *range.last <= range.first) {
    throw Error("--frames '" + std::string(text) + "' selects no frame (end must be after start)");
  }
  return range;
}

}  // namespace relight::app
