#pragma once
// The light set of the light-extraction stage (lights/light_set.h) as MrScene lights: a
// directional light keeps its direction and delivers its `power` as irradiance; a point light
// keeps its position and radiant intensity. The real/virtual flag carries over.
#include "relight/lights/light_set.h"
#include "relight/render/scene/mr_scene.h"

namespace relight::render {

void add_lights(MrScene& scene, const lights::LightSet& lights);

}  // namespace relight::render
