// Fuzzes the TUM RGB-D folder reader (capture/tum_sequence.h): one input holds rgb.txt, depth.txt
// and optionally groundtruth.txt and scene.json (split at "----" lines, see fuzz_input.h); the
// folder is opened as `relight replay` opens it (lists parsed, colour and depth associated, poses
// interpolated, intrinsics and depth scale from scene.json). relight::Error is the answer to bad
// input; any other exception, a crash or a sanitizer report is a finding.
#include <cmath>

#include "fuzz_input.h"
#include "relight/capture/tum_sequence.h"
#include "relight/core/error.h"

namespace {

void check_opened(const relight::capture::TumSequence& sequence) {
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const relight::capture::TumFrame& frame = sequence.frame(i);
    if (!std::isfinite(frame.depth_timestamp) || !std::isfinite(frame.color_timestamp)) std::abort();
    if (frame.camera_to_world && !frame.camera_to_world->matrix().allFinite()) std::abort();
  }
  if (!(sequence.depth_scale() > 0)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using relight::fuzz::scratch;
  const auto files = relight::fuzz::split_files(relight::fuzz::as_text(data, size));
  const char* names[] = {"rgb.txt", "depth.txt", "groundtruth.txt", "scene.json"};
  for (std::size_t i = 0; i < std::size(names); ++i) {
    if (i < files.size()) {
      scratch().write(names[i], files[i]);
    } else {
      scratch().remove(names[i]);
    }
  }
  try {
    check_opened(relight::capture::TumSequence::open(scratch().path()));
  } catch (const relight::Error&) {
  }
  return 0;
}
