#include "relight/render/scene/scene_lights.h"

namespace relight::render {

void add_lights(MrScene& scene, const lights::LightSet& lights) {
  for (const lights::Light& light : lights.lights) {
    if (light.kind == relight::lights::LightKind::Spot) {
      scene.lights.push_back(spot_light(light.position.cast<float>(), light.axis.normalized().cast<float>(),
                                        static_cast<float>(light.cone_degrees), static_cast<float>(light.inner_degrees),
                                        light.power.cast<float>(), light.real));
      continue;
    }
    MrLight out;
    out.kind = light.kind == relight::lights::LightKind::Directional ? LightKind::Directional : LightKind::Point;
    out.direction = light.direction.normalized().cast<float>();
    out.position = light.position.cast<float>();
    out.intensity = light.power.cast<float>();
    out.real = light.real;
    scene.lights.push_back(out);
  }
}

}  // namespace relight::render
