#include "relight/synth/sequence.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::synth {

namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

Json vec(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json pose_json(const Pose& pose) {
  const auto tum = pose_to_tum(pose);
  Json rows = Json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back(Json::array({pose.matrix()(r, 0), pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3)}));
  }
  return {{"position", {tum[0], tum[1], tum[2]}}, {"quaternion_xyzw", {tum[3], tum[4], tum[5], tum[6]}}, {"matrix", rows}};
}

Json shape_json(const Shape& shape) {
  return std::visit(
      [](const auto& s) -> Json {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, Sphere>) return {{"type", "sphere"}, {"centre", vec(s.centre)}, {"radius", s.radius}};
        if constexpr (std::is_same_v<S, Box>) return {{"type", "box"}, {"min", vec(s.min)}, {"max", vec(s.max)}};
        if constexpr (std::is_same_v<S, Rect>) {
          return {{"type", "rectangle"}, {"centre", vec(s.centre)}, {"normal", vec(s.normal)}, {"u", vec(s.u)},
                  {"v", vec(s.v)},       {"half_u", s.half_u},       {"half_v", s.half_v}};
        }
        if constexpr (std::is_same_v<S, Cylinder>) {
          return {{"type", "cylinder_z"}, {"base", vec(s.base)}, {"radius", s.radius}, {"height", s.height}};
        }
      },
      shape);
}

Json materials_json(const Scene& scene) {
  Json materials = Json::array();
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    materials.push_back({{"id", i + 1}, {"name", m.name}, {"kd", vec(m.kd)}, {"ks", m.ks}, {"n", m.n}});
  }
  return materials;
}

Json objects_json(const Scene& scene) {
  Json objects = Json::array();
  for (const Object& o : scene.objects) {
    Json object = {{"name", o.name}, {"material", scene.materials[static_cast<std::size_t>(o.material)].name},
                   {"material_id", o.material + 1}};
    object.update(shape_json(o.shape));
    objects.push_back(object);
  }
  return objects;
}

Json lights_json(const Scene& scene) {
  Json lights = Json::array();
  for (const PointLight& l : scene.lights) {
    Json light = {{"type", l.spot() ? "spot" : "point"},
                  {"position", vec(l.position)},
                  {"direction", nullptr},
                  {"colour", vec(l.colour)},
                  {"intensity", l.intensity},
                  {"power", vec(l.colour * l.intensity)},
                  {"units", l.spot() ? "W/sr per unit colour on the axis; power = colour * intensity"
                                     : "W/sr per unit colour; power = colour * intensity"},
                  {"probe_radius", l.radius},
                  {"real", true}};
    if (l.spot())
      light.update({{"axis", vec(l.axis)}, {"cone_degrees", l.cone_degrees}, {"inner_degrees", l.inner_degrees}});
    lights.push_back(light);
  }
  return lights;
}

Json tag_json(const TagDecal& tag) {
  Json corners = Json::array();
  for (const auto& c : tag.corners_world()) corners.push_back(vec(c));
  Pose pose = Pose::Identity();
  pose.linear().col(0) = tag.x_axis;
  pose.linear().col(1) = tag.y_axis;
  pose.linear().col(2) = tag.z_axis();
  pose.translation() = tag.centre;
  char code[32];
  std::snprintf(code, sizeof code, "0x%llx", static_cast<unsigned long long>(tag.code));
  return {{"family", "tag36h11"}, {"id", tag.id}, {"code", code}, {"size", tag.size},
          {"corners_world", corners},
          {"corner_order", "AprilTag order: tag frame (-s/2,+s/2), (+s/2,+s/2), (+s/2,-s/2), (-s/2,-s/2)"},
          {"pose", pose_json(pose)},
          {"pose_convention", "tag-to-world; tag frame x right, y down in the tag image, z into the tag"}};
}

Json noise_json(const SynthOptions& options) {
  const KinectNoiseOptions& k = options.kinect;
  Json noise = {{"model", to_string(options.noise)}};
  if (options.noise == NoiseModel::None) return noise;
  noise.update({{"axial_sigma", "0.0012 + 0.0019 * (z - 0.4)^2 (Nguyen, Izadi, Lovell 2012)"},
                {"axial", k.axial},
                {"lateral_sigma_px", k.lateral_sigma_px},
                {"quantise", k.quantise},
                {"baseline_m", k.baseline_m},
                {"focal_px", k.focal_px},
                {"subpixel", k.subpixel},
                {"min_depth", k.min_depth},
                {"max_depth", k.max_depth},
                {"grazing_angle_deg", k.grazing_angle_deg},
                {"edge_dropouts", k.edge_dropouts},
                {"edge_radius_px", k.edge_radius_px},
                {"edge_threshold_m", k.edge_threshold_m},
                {"edge_threshold_rel", k.edge_threshold_rel},
                {"edge_dropout_probability", k.edge_dropout_probability}});
  return noise;
}

Json probe_json(const LightProbe& probe) {
  const FisheyeCamera& c = probe.camera;
  Pose pose = Pose::Identity();
  pose.linear() = probe.probe_to_world;
  pose.translation() = probe.position;
  return {{"file", "probe.hdr"}, {"model", "equidistant"}, {"cx", c.cx}, {"cy", c.cy}, {"radius", c.radius},
          {"max_theta", c.max_theta}, {"width", c.width}, {"height", c.height},
          {"samples_per_axis", probe.samples_per_axis}, {"pose", pose_json(pose)},
          {"pose_convention", "probe-to-world; probe frame x right, y down in the image, z = optical axis"}};
}

// The lamp's calibration, and the replay options that give it to relight.
Json pocket_lamp_json(const Scene& scene) {
  const PocketLamp lamp = pocket_lamp(scene, 0.0);
  const Eigen::Vector3d power = lamp.light.colour * lamp.light.intensity;
  char options[256];
  std::snprintf(options, sizeof options,
                "--real-spot-tag %d,%g,%g,%g,%g,%g,%g --real-spot-tag-offset %g,%g,%g,%g,%g,%g", lamp.tag.id,
                lamp.tag.size, lamp.light.cone_degrees, lamp.light.intensity, lamp.light.colour.x(),
                lamp.light.colour.y(), lamp.light.colour.z(), lamp.position_in_tag.x(), lamp.position_in_tag.y(),
                lamp.position_in_tag.z(), lamp.axis_in_tag.x(), lamp.axis_in_tag.y(), lamp.axis_in_tag.z());
  return {{"tag_family", "tag36h11"},
          {"tag_id", lamp.tag.id},
          {"tag_size", lamp.tag.size},
          {"position_in_tag", vec(lamp.position_in_tag)},
          {"axis_in_tag", vec(lamp.axis_in_tag)},
          {"cone_degrees", lamp.light.cone_degrees},
          {"inner_degrees", lamp.light.inner_degrees},
          {"power", vec(power)},
          {"tag_frame", "x right, y down in the tag image, z into the tag"},
          {"replay_options", options},
          {"per_frame", "the lamp's light is the spot of gt/lights/<timestamp>.json"}};
}

Json intrinsics_json(const PinholeIntrinsics& k) {
  return {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}, {"width", k.width}, {"height", k.height}};
}

}  // namespace

PinholeIntrinsics synth_intrinsics(const SynthOptions& options) {
  PinholeIntrinsics k = PinholeIntrinsics::kinect_v1();
  const double sx = static_cast<double>(options.width) / k.width, sy = static_cast<double>(options.height) / k.height;
  // Scale about pixel corners: centre (cx + 0.5) scales, the -0.5 restores centre-of-pixel indexing.
  return {k.fx * sx, k.fy * sy, (k.cx + 0.5) * sx - 0.5, (k.cy + 0.5) * sy - 0.5, options.width, options.height};
}

std::string scene_json(const Scene& scene, const SynthOptions& options) {
  Json json = {{"generator", "relight synth"},
               {"units", "metres, seconds, linear RGB radiance"},
               {"world_up", {0, 0, 1}},
               {"intrinsics", intrinsics_json(synth_intrinsics(options))},
               {"depth_scale", kSynthDepthScale},
               {"registered", "colour and depth share one camera (these intrinsics, same pose)"},
               {"frames", options.frames},
               {"first_timestamp", frame_timestamp(0)},
               {"fps", 30},
               {"trajectory", to_string(options.trajectory)},
               {"seed", options.seed},
               {"noise", noise_json(options)},
               {"color",
                {{"gains", options.color.gains},
                 {"exposure", options.color.exposure},
                 {"encoding", "sRGB 8-bit"},
                 {"blur_sigma_px", options.camera.blur_sigma_px},
                 {"noise",
                  {{"model", "sigma(I)^2 = floor + gain * I, 8-bit codes"},
                   {"floor", options.camera.noise_floor},
                   {"gain", options.camera.noise_gain}}}}},
               {"shading",
                "L = kd*Lenv + sum_visible E*(kd/pi + ks*(n+2)/(2pi)*max(0,r.v)^n), "
                "E = colour*intensity*max(0,n.l)/d^2"},
               {"materials", materials_json(scene)},
               {"objects", objects_json(scene)},
               {"lights", lights_json(scene)},
               {"environment", {{"type", "constant"}, {"radiance", vec(scene.environment)}}}};
  if (!scene.tags.empty()) json["tag"] = tag_json(scene.tags.front());
  json["probe"] = probe_json(default_probe(scene));
  const LightAnimationOptions& animation = options.light_animation;
  if (animation.kind != LightAnimation::None) {
    json["light_animation"] = {{"kind", name_of(kLightAnimationNames, animation.kind)},
                               {"light", animation.light},
                               {"event_frame", light_event_frame(animation, options.frames)},
                               {"dim_to", animation.dim_to},
                               {"orbit_degrees", animation.orbit_degrees},
                               {"orbit_height", animation.orbit_height},
                               {"probe_stream", "probe.txt"},
                               {"lights_per_frame", "gt/lights/<timestamp>.json"}};
  }
  if (animation.kind == LightAnimation::PocketLamp) json["pocket_lamp"] = pocket_lamp_json(scene);
  json["ground_truth"] = {{"depth", "gt/depth/<timestamp>.exr"}, {"normals", "gt/normals/<timestamp>.exr"},
                          {"albedo", "gt/albedo/<timestamp>.png"}, {"material", "gt/material/<timestamp>.png"},
                          {"material_background", 0}};
  return json.dump(2) + "\n";
}

std::string frame_lights_json(const Scene& scene) {
  return Json{{"lights", lights_json(scene)},
              {"units", "point and spot lights: power = radiant intensity (a spot's on its axis), W/sr per channel"}}
             .dump(2) +
         "\n";
}

void validate_synth_options(const SynthOptions& options) {
  if (options.frames < 0) throw Error("synth: number of frames must not be negative");
  if (options.width < 2 || options.height < 2) throw Error("synth: image size must be at least 2x2");
  for (double g : options.color.gains) {
    if (!(g > 0.0)) throw Error("synth: white-balance gains must be positive");
  }
  if (!(options.color.exposure > 0.0)) throw Error("synth: exposure must be positive");
  if (!(options.probe_noise >= 0.0 && options.probe_noise < 1.0)) throw Error("synth: probe noise must be in [0, 1)");
}

}  // namespace relight::synth
