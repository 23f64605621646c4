#include "relight/lights/light_smoothing.h"

#include <cmath>

namespace relight::lights {

LightSet smooth_lights(const LightSet& current, const LightSet* previous, const LightSmoothingOptions& options) {
  if (!previous || previous->lights.size() != current.lights.size()) return current;
  const double before = luminance(total_power(*previous));
  const double now = luminance(total_power(current));
  if (std::abs(now - before) > options.reset_change * std::max(before, 1e-30)) return current;

  const double cos_jitter = std::cos(options.max_jitter);
  LightSet smoothed = current;
  for (std::size_t i = 0; i < current.lights.size(); ++i) {
    const Light& old_light = previous->lights[i];
    Light& light = smoothed.lights[i];
    if (old_light.kind != light.kind || old_light.real != light.real) continue;
    if (light.kind == LightKind::Directional && old_light.direction.dot(light.direction) < cos_jitter) continue;
    const double keep = 1.0 - options.blend;
    light.power = options.blend * light.power + keep * old_light.power;
    light.position = options.blend * light.position + keep * old_light.position;
    const Eigen::Vector3d direction = options.blend * light.direction + keep * old_light.direction;
    if (direction.norm() > 0.0) light.direction = direction.normalized();
  }
  return smoothed;
}

void LightSmoothingStage::declare(StageBuilder& builder) {
  input_ = builder.read(buffers_.input);
  previous_ = builder.read_previous(buffers_.output);
  output_ = builder.write(buffers_.output);
}

void LightSmoothingStage::run(StageContext& context) {
  // The previous version is copied first: the output buffer may be the same object.
  const LightSet* previous = context.get(previous_);
  LightSet smoothed = smooth_lights(context.get(input_), previous, options_);
  context.get(output_) = std::move(smoothed);
}

}  // namespace relight::lights
