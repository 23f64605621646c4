#include "relight/truth/tag_layout.h"

namespace relight::truth {

capture::TagLayout tag_layout(const synth::Scene& scene) {
  capture::TagLayout layout;
  for (const auto& decal : scene.tags) {
    capture::TagLayout::Tag tag;
    tag.id = decal.id;
    tag.size = decal.size;
    const auto corners = decal.corners_world();
    for (std::size_t k = 0; k < 4; ++k) tag.corners_world[k] = corners[k];
    layout.tags.push_back(tag);
  }
  return layout;
}

}  // namespace relight::truth
