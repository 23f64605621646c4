#include "tracked_lamp_stage.h"

#include <cmath>
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

TrackedLampStage::TrackedLampStage(TrackedLamp lamp) : lamp_(std::move(lamp)) {
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
    auto camera_to_tag = capture::estimate_camera_pose(detections, tag_alone_, frame.intrinsics);
    if (camera_to_tag) {
      camera_to_tag =
          capture::refine_with_depth(*camera_to_tag, detections, tag_alone_, frame.intrinsics, context.get(depth_));
      seen = Pose(*frame.camera_to_world * camera_to_tag->camera_to_world.inverse());
    }
  }
  if (seen) {
    ++frames_seen_;
    last_ = lamp_light(lamp_, *seen);
  } else if (last_) {
    ++frames_held_;
  }
  lights::LightSet& out = context.get(lights_);
  out = context.get(room_);
  if (last_) out.lights.push_back(*last_);
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
  return json;
}

}  // namespace relight::app
