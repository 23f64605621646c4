#pragma once
// The names of the lights' frame-graph buffers (buffer_name.h).
#include "relight/core/buffer_name.h"
#include "relight/lights/light_set.h"

namespace relight::lights {

inline constexpr BufferName<LightSet> kLightsRaw{"lights_raw"};  ///< this frame's extracted lights
inline constexpr BufferName<LightSet> kLights{"lights"};         ///< the real lights every stage uses

}  // namespace relight::lights
