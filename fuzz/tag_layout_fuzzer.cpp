// Fuzzes the AprilTag layout reader (`--markers FILE`, capture/tag_layout.h, parse_tag_layout):
// the input is the layout JSON (or a scene.json that holds one). relight::Error is the answer to a
// malformed layout; any other exception, a crash or a sanitizer report is a finding. A parsed
// layout must be one the pose solver can use: positive finite tag sizes, finite corners, each id
// once.
#include <cstdlib>
#include <set>

#include "fuzz_input.h"
#include "relight/capture/tag_layout.h"
#include "relight/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const relight::capture::TagLayout layout =
        relight::capture::parse_tag_layout(relight::fuzz::as_text(data, size), "layout.json");
    std::set<int> ids;
    for (const auto& tag : layout.tags) {
      if (!(tag.size > 0.0 && std::isfinite(tag.size))) std::abort();
      for (const auto& corner : tag.corners_world)
        if (!corner.allFinite()) std::abort();
      if (!ids.insert(tag.id).second) std::abort();
      if (layout.find(tag.id) == nullptr) std::abort();
    }
  } catch (const relight::Error&) {
  }
  return 0;
}
