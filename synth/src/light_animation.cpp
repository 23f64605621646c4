#include "relight/synth/light_animation.h"

#include <Eigen/Geometry>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "relight/core/error.h"

namespace relight::synth {

int light_event_frame(const LightAnimationOptions& animation, int frames) {
  return animation.event_frame >= 0 ? animation.event_frame : frames / 2;
}

SequenceLightAnimation light_animation_of_scene_json(const std::string& text, const std::string& source) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object()) throw Error(source + ": not valid JSON");
  SequenceLightAnimation out;
  out.frames = json.value("frames", 0);
  if (!json.contains("light_animation")) return out;
  const nlohmann::json& section = json["light_animation"];
  try {
    out.animation.kind =
        parse_named(kLightAnimationNames, "light_animation.kind", section.at("kind").get<std::string>());
    out.animation.light = section.at("light").get<int>();
    out.animation.event_frame = section.at("event_frame").get<int>();
    out.animation.dim_to = section.at("dim_to").get<double>();
    out.animation.orbit_degrees = section.at("orbit_degrees").get<double>();
  } catch (const nlohmann::json::exception& error) {
    throw Error(source + ": light_animation: " + error.what());
  } catch (const Error& error) {
    throw Error(source + ": " + error.what());
  }
  return out;
}

Scene scene_at_frame(const Scene& scene, const LightAnimationOptions& animation, int frame, int frames) {
  if (animation.kind == LightAnimation::None) return scene;
  if (animation.light < 0 || animation.light >= static_cast<int>(scene.lights.size())) {
    throw Error("synth: light animation: the scene has no light " + std::to_string(animation.light) + " (it has " +
                std::to_string(scene.lights.size()) + ")");
  }
  if (!(animation.dim_to >= 0.0 && animation.dim_to <= 1.0))
    throw Error("synth: light animation: dim_to must be in [0, 1]");
  if (!std::isfinite(animation.orbit_degrees)) throw Error("synth: light animation: the orbit angle must be finite");
  const int event = light_event_frame(animation, frames);
  if (event >= frames && (animation.kind == LightAnimation::SwitchOn || animation.kind == LightAnimation::SwitchOff)) {
    throw Error("synth: light animation: the switch frame " + std::to_string(event) + " is past the last frame");
  }
  Scene out = scene;
  const auto index = static_cast<std::size_t>(animation.light);
  PointLight& light = out.lights[index];
  const double t = frames > 1 ? static_cast<double>(frame) / (frames - 1) : 0.0;
  bool off = false;
  switch (animation.kind) {
    case LightAnimation::None: break;
    case LightAnimation::SwitchOn: off = frame < event; break;
    case LightAnimation::SwitchOff: off = frame >= event; break;
    case LightAnimation::Dim: light.intensity *= 1.0 + (animation.dim_to - 1.0) * t; break;
    case LightAnimation::Orbit: {
      const double angle = animation.orbit_degrees * t * std::numbers::pi / 180.0;
      const Eigen::Vector3d axis_point(scene.look_at.x(), scene.look_at.y(), light.position.z());
      light.position = axis_point + Eigen::AngleAxisd(angle, world_up()) * (light.position - axis_point);
      break;
    }
  }
  if (off) out.lights.erase(out.lights.begin() + static_cast<std::ptrdiff_t>(index));
  return out;
}

}  // namespace relight::synth
