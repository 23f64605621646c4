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
    out.animation.orbit_height = section.value("orbit_height", 0.0);
  } catch (const nlohmann::json::exception& error) {
    throw Error(source + ": light_animation: " + error.what());
  } catch (const Error& error) {
    throw Error(source + ": " + error.what());
  }
  return out;
}

PocketLamp pocket_lamp(const Scene& scene, double degrees) {
  using Eigen::Vector3d;
  // Held 0.35 m above the table on its far side as the default camera path sees it (the camera
  // starts at azimuth atan2(-0.9, 1.2) about look_at; the lamp is on the opposite side, low
  // enough for the card to stay inside a Kinect's 45-degree vertical field of view).
  const Vector3d far_side = Vector3d(-0.8, 0.6, 0.0);
  const Vector3d pivot = scene.look_at + 0.55 * far_side + Vector3d(0, 0, 0.35);
  const Vector3d facing = Vector3d(1.2, -0.9, 0.1).normalized();  // the card's face, towards the camera path
  const Vector3d aim_at = scene.tags.empty() ? scene.look_at : scene.tags.front().centre;
  PocketLamp lamp;
  lamp.tag.code = kTag36h11Codes[1];
  lamp.tag.id = 1;
  lamp.tag.size = 0.16;
  lamp.tag.centre = pivot;
  const Vector3d z = -facing;  // tag frame z points into the tag
  lamp.tag.x_axis = z.cross(world_up()).normalized();
  lamp.tag.y_axis = z.cross(lamp.tag.x_axis);
  lamp.tag.black_material = scene.material_index("tag_black");
  lamp.tag.white_material = scene.material_index("tag_white");
  Eigen::Matrix3d tag_to_world;
  tag_to_world << lamp.tag.x_axis, lamp.tag.y_axis, lamp.tag.z_axis();
  // The light hangs 12 cm below the tag's centre (beneath the card's lower edge), aimed at the table tag.
  lamp.position_in_tag = Vector3d(0.0, 0.12, 0.0);
  const Vector3d light_world = pivot + tag_to_world * lamp.position_in_tag;
  lamp.axis_in_tag = tag_to_world.transpose() * (aim_at - light_world).normalized();
  // Turned about the vertical through the card's centre.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, world_up()).toRotationMatrix();
  lamp.tag.x_axis = turn * lamp.tag.x_axis;
  lamp.tag.y_axis = turn * lamp.tag.y_axis;
  tag_to_world = turn * tag_to_world;
  const double half = 0.5 * lamp.tag.size * 10.0 / 8.0 + 0.01;  // the white margin is one cell, then a 1 cm border
  lamp.card = Rect{pivot, -lamp.tag.z_axis(), lamp.tag.x_axis, lamp.tag.y_axis, half, half};
  lamp.light.position = pivot + tag_to_world * lamp.position_in_tag;
  lamp.light.axis = tag_to_world * lamp.axis_in_tag;
  lamp.light.colour = Vector3d(1.0, 0.9, 0.75);
  lamp.light.intensity = 6.0;
  lamp.light.radius = 0.02;
  lamp.light.cone_degrees = 25.0;
  lamp.light.inner_degrees = 20.0;
  return lamp;
}

Scene scene_at_frame(const Scene& scene, const LightAnimationOptions& animation, int frame, int frames) {
  if (animation.kind == LightAnimation::None) return scene;
  if (!std::isfinite(animation.orbit_degrees)) throw Error("synth: light animation: the orbit angle must be finite");
  const double t = frames > 1 ? static_cast<double>(frame) / (frames - 1) : 0.0;
  if (animation.kind == LightAnimation::PocketLamp) {
    Scene out = scene;
    PocketLamp lamp = pocket_lamp(scene, animation.orbit_degrees * (t - 0.5));
    lamp.tag.object = static_cast<int>(out.objects.size());
    out.objects.push_back({"pocket_lamp_card", lamp.card, lamp.tag.white_material});
    out.tags.push_back(lamp.tag);
    out.lights.push_back(lamp.light);
    return out;
  }
  if (animation.light < 0 || animation.light >= static_cast<int>(scene.lights.size())) {
    throw Error("synth: light animation: the scene has no light " + std::to_string(animation.light) + " (it has " +
                std::to_string(scene.lights.size()) + ")");
  }
  if (!(animation.dim_to >= 0.0 && animation.dim_to <= 1.0))
    throw Error("synth: light animation: dim_to must be in [0, 1]");
  if (!(animation.orbit_height >= 0.0 && std::isfinite(animation.orbit_height)))
    throw Error("synth: light animation: the orbit height must be a finite height above the floor");
  const int event = light_event_frame(animation, frames);
  if (event >= frames && (animation.kind == LightAnimation::SwitchOn || animation.kind == LightAnimation::SwitchOff)) {
    throw Error("synth: light animation: the switch frame " + std::to_string(event) + " is past the last frame");
  }
  Scene out = scene;
  const auto index = static_cast<std::size_t>(animation.light);
  PointLight& light = out.lights[index];
  bool off = false;
  switch (animation.kind) {
    case LightAnimation::None:
    case LightAnimation::PocketLamp: break;
    case LightAnimation::SwitchOn: off = frame < event; break;
    case LightAnimation::SwitchOff: off = frame >= event; break;
    case LightAnimation::Dim: light.intensity *= 1.0 + (animation.dim_to - 1.0) * t; break;
    case LightAnimation::Orbit: {
      const double angle = animation.orbit_degrees * t * std::numbers::pi / 180.0;
      if (animation.orbit_height > 0.0) light.position.z() = animation.orbit_height;
      const Eigen::Vector3d axis_point(scene.look_at.x(), scene.look_at.y(), light.position.z());
      light.position = axis_point + Eigen::AngleAxisd(angle, world_up()) * (light.position - axis_point);
      break;
    }
  }
  if (off) out.lights.erase(out.lights.begin() + static_cast<std::ptrdiff_t>(index));
  return out;
}

}  // namespace relight::synth
