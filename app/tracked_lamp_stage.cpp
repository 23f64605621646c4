#include "tracked_lamp_stage.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "mixed_reality_scene.h"
#include "number_list.h"
#include "relight/capture/marker_pose.h"
#include "relight/core/error.h"

namespace relight::app {

namespace {
nlohmann::ordered_json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

TrackedLamp parse_tracked_lamp(const std::string& tag, const std::string& offset) {
  const std::vector<double> v = parse_number_list<double>("--real-spot-tag", tag);
  const std::string what = "--real-spot-tag '" + tag + "'";
  if (v.size() != 4 && v.size() != 7) throw Error(what + " needs id,size,angle_degrees,intensity[,r,g,b]");
  TrackedLamp lamp;
  if (!(v[0] >= 0.0 && v[0] == std::floor(v[0]) && v[0] < 1e6))
    throw Error(what + ": the tag id must be a whole number");
  lamp.tag_id = static_cast<int>(v[0]);
  if (!(v[1] > 0.0 && v[1] < 10.0)) throw Error(what + ": the tag size must be in (0, 10) metres");
  lamp.tag_size = v[1];
  if (!(v[2] > 0.0 && v[2] < 90.0)) throw Error(what + ": the angle must be in (0, 90) degrees");
  lamp.cone_degrees = v[2];
  lamp.inner_degrees = static_cast<double>(kSpotInnerFraction * static_cast<float>(v[2]));  // as --real-spot
  lamp.power = parse_intensity("--real-spot-tag", tag, v, 3);
  if (offset.empty()) return lamp;
  const std::vector<double> o = parse_number_list<double>("--real-spot-tag-offset", offset);
  if (o.size() != 3 && o.size() != 6)
    throw Error("--real-spot-tag-offset '" + offset + "' needs x,y,z[,axis_x,axis_y,axis_z] in the tag's frame");
  lamp.position_in_tag = Eigen::Vector3d(o[0], o[1], o[2]);
  if (o.size() == 6) {
    const Eigen::Vector3d axis(o[3], o[4], o[5]);
    if (!(axis.norm() > 1e-9)) throw Error("--real-spot-tag-offset '" + offset + "': the axis must not be zero");
    lamp.axis_in_tag = axis.normalized();
  }
  return lamp;
}

lights::Light lamp_light(const TrackedLamp& lamp, const Pose& tag_to_world) {
  lights::Light light;
  light.kind = lights::LightKind::Spot;
  light.real = true;
  light.position = tag_to_world * lamp.position_in_tag;
  light.axis = (tag_to_world.linear() * lamp.axis_in_tag).normalized();
  light.cone_degrees = lamp.cone_degrees;
  light.inner_degrees = lamp.inner_degrees;
  light.power = lamp.power;
  return light;
}

double lamp_irradiance_at(const lights::Light& lamp, const Eigen::Vector3d& point) {
  const Eigen::Vector3d to_point = point - lamp.position;
  if (!(to_point.squaredNorm() > 0.0)) return 0.0;
  return lights::luminance(lamp.power) * lights::spot_falloff(lamp, to_point.normalized()) / to_point.squaredNorm();
}

lights::LightSet without_lamp_in_probe(const lights::LightSet& room, const lights::Light& lamp,
                                       const Eigen::Vector3d& probe_position, Eigen::Vector3d& removed) {
  removed.setZero();
  // A spot shows in the probe only when the probe is inside its cone.
  if (!(lamp_irradiance_at(lamp, probe_position) > 0.0)) return room;
  const Eigen::Vector3d to_lamp = lamp.position - probe_position;
  const double cos_limit = std::cos(kLampInProbeDegrees * std::numbers::pi / 180.0);
  lights::LightSet out;
  for (const lights::Light& light : room.lights) {
    const bool lamps = light.real && light.kind == lights::LightKind::Directional &&
                       light.direction.normalized().dot(to_lamp.normalized()) >= cos_limit;
    if (lamps)
      removed += light.power;
    else
      out.lights.push_back(light);
  }
  return out;
}

TrackedLampStage::TrackedLampStage(TrackedLamp lamp, std::optional<Eigen::Vector3d> probe_position)
    : lamp_(std::move(lamp)), probe_position_(std::move(probe_position)) {
  // The tag alone, in its own frame: the "camera pose" PnP finds against it is camera-to-tag.
  capture::TagLayout::Tag tag;
  tag.id = lamp_.tag_id;
  tag.size = lamp_.tag_size;
  const double h = lamp_.tag_size / 2.0;
  tag.corners_world = {Eigen::Vector3d(-h, h, 0), Eigen::Vector3d(h, h, 0), Eigen::Vector3d(h, -h, 0),
                       Eigen::Vector3d(-h, -h, 0)};
  tag_alone_.tags.push_back(tag);
}

void TrackedLampStage::declare(StageBuilder& builder) {
  detections_ = builder.read(capture::kTagDetections);
  depth_ = builder.read(kDepth);
  frame_ = builder.read(kFrame);
  room_ = builder.read(kRoomLights);
  lights_ = builder.write(lights::kLights);
}

void TrackedLampStage::run(StageContext& context) {
  ++frames_;
  std::optional<Pose> seen;  // the tag's pose in the world this frame
  const FrameInfo& frame = context.get(frame_);
  if (frame.camera_to_world) {
    const std::vector<capture::TagDetection>& detections = context.get(detections_).tags;
    // A hand-held lamp's small tag is often seen head-on: its tilt always comes from its depth.
    const auto camera_to_tag =
        capture::estimate_camera_pose(detections, tag_alone_, frame.intrinsics, context.get(depth_), 90.0);
    if (camera_to_tag) seen = Pose(*frame.camera_to_world * camera_to_tag->camera_to_world.inverse());
  }
  if (seen) {
    ++frames_seen_;
    last_ = lamp_light(lamp_, *seen);
  } else if (last_) {
    ++frames_held_;
  }
  lights::LightSet& out = context.get(lights_);
  out = context.get(room_);
  if (!last_) return;
  const double at_probe = probe_position_ ? lamp_irradiance_at(*last_, *probe_position_) : 0.0;
  if (at_probe > 0.0) {
    Eigen::Vector3d removed;
    const std::size_t before = out.lights.size();
    out = without_lamp_in_probe(out, *last_, *probe_position_, removed);
    ++frames_lamp_in_probe_;
    lights_taken_out_ += static_cast<int>(before - out.lights.size());
    taken_out_irradiance_ += lights::luminance(removed);
    lamp_irradiance_ += at_probe;
  }
  out.lights.push_back(*last_);
}

nlohmann::ordered_json TrackedLampStage::summary() const {
  nlohmann::ordered_json json{{"tag_id", lamp_.tag_id},
                              {"frames", frames_},
                              {"frames_seen", frames_seen_},
                              {"frames_held", frames_held_},
                              {"frames_before_first_sighting", frames_ - frames_seen_ - frames_held_}};
  if (last_) {
    json["last_position"] = vec(last_->position);
    json["last_axis"] = vec(last_->axis);
  }
  if (probe_position_) {
    json["probe"] = {{"position", vec(*probe_position_)},
                     {"frames_lamp_in_probe", frames_lamp_in_probe_},
                     {"lights_taken_out", lights_taken_out_},
                     {"taken_out_irradiance", taken_out_irradiance_},
                     {"lamp_irradiance", lamp_irradiance_}};
  }
  return json;
}

}  // namespace relight::app
