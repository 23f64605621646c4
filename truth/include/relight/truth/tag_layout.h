#pragma once
// The synthetic scene's AprilTags as a capture TagLayout: the ground truth that the marker pose
// stage is tested and benchmarked against.
#include "relight/capture/tag_layout.h"
#include "relight/synth/scene.h"

namespace relight::truth {

[[nodiscard]] capture::TagLayout tag_layout(const synth::Scene& scene);

}  // namespace relight::truth
