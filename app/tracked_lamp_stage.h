#pragma once
// A tracked real lamp (dissertation §5.2.12, Knecht 2010 §6: a pocket lamp carrying a marker): a
// real spot light whose pose comes from an AprilTag of its own, re-posed every frame. The tag's
// pose in the camera (PnP on its four corners with the distance refined from depth, as the
// camera's marker pose does: capture/marker_pose.h) and the camera's tracked pose in the world
// give the tag's pose in the world; the lamp's calibration - where its light sits in the tag's
// frame and where it shines - places the light:
//   tag_to_world = camera_to_world * inverse(camera_to_tag)
//   position = tag_to_world * position_in_tag,  axis = R(tag_to_world) * axis_in_tag
//
// Stage TrackedLampStage ("tracked_lamp")
//   reads:  "tag_detections" (TagDetections, capture/tag_detection_stage.h: shared with the
//           marker pose), "depth" (DepthMap), "frame" (FrameInfo: the intrinsics and the tracked
//           camera_to_world), "room_lights" (LightSet: the other real lights)
//   writes: "lights" (LightSet): the room's lights and the lamp, a real spot light. While the
//           tag is out of view, or the camera has no pose, the lamp stays where it was last seen
//           (a lamp does not vanish when its marker turns away); before its first sighting it is
//           left out.
// When the room's lights come from a light probe that the lamp shines on, the probe saw the lamp
// too, and its lights hold it a second time: the directional lights within kLampInProbeDegrees of
// the lamp as seen from the probe (`probe_position`) are taken out - the lamp's own samples of
// the probe (importance sampling puts the light of a bright spot into the samples that land on
// it), whose light the tracked lamp now brings, posed and shaped.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "relight/capture/tag_detection_stage.h"
#include "relight/capture/tag_layout.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/pose.h"
#include "relight/core/rgbd_frame.h"
#include "relight/lights/buffers.h"
#include "relight/lights/light_set.h"

namespace relight::app {

/// The real lights before the tracked lamp joins them.
inline constexpr BufferName<lights::LightSet> kRoomLights{"room_lights"};

/// A lamp and its tag: the light's position (metres) and axis in the tag's frame (x right, y down
/// in the tag image, z into the tag), its cone and its radiant intensity on the axis.
struct TrackedLamp {
  int tag_id = 0;
  double tag_size = 0.0;  ///< metres, the edge of the tag's black square
  Eigen::Vector3d position_in_tag = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_in_tag = Eigen::Vector3d::UnitZ();  ///< default: it shines where the tag faces away from
  double cone_degrees = 30.0;
  double inner_degrees = 24.0;
  Eigen::Vector3d power = Eigen::Vector3d::Ones();  ///< W/sr per channel on the axis
};

/// Parses `--real-spot-tag ID,SIZE,ANGLE,INTENSITY[,R,G,B]` (the tag's id and black-square edge
/// in metres, the cone's half-angle in degrees, the radiant intensity times the colour) and
/// `--real-spot-tag-offset X,Y,Z[,AX,AY,AZ]` (the light's position and axis in the tag's frame;
/// empty: at the tag's centre, shining along +z). Throws relight::Error naming the option.
[[nodiscard]] TrackedLamp parse_tracked_lamp(const std::string& tag, const std::string& offset);

/// The lamp's real spot light for the tag's pose in the world.
[[nodiscard]] lights::Light lamp_light(const TrackedLamp& lamp, const Pose& tag_to_world);

/// How far (degrees) from the lamp's direction, seen from the probe, a probe light is the lamp's:
/// the lamp's few pixels, a probe pixel's width and what the light smoothing moves a light by.
inline constexpr double kLampInProbeDegrees = 6.0;

/// The luminance of the irradiance `lamp` delivers at `point` (normal incidence; 0 outside its cone).
[[nodiscard]] double lamp_irradiance_at(const lights::Light& lamp, const Eigen::Vector3d& point);

/// The lights of `room` without the probe's samples of a lamp at `lamp` as a probe at
/// `probe_position` sees it (none when the probe is outside the lamp's cone); `removed` gets the
/// irradiance (RGB, normal incidence) of what was taken out.
[[nodiscard]] lights::LightSet without_lamp_in_probe(const lights::LightSet& room, const lights::Light& lamp,
                                                     const Eigen::Vector3d& probe_position, Eigen::Vector3d& removed);

class TrackedLampStage final : public Stage {
 public:
  /// `probe_position`: where the probe sits when the room's lights come from one (else none).
  explicit TrackedLampStage(TrackedLamp lamp, std::optional<Eigen::Vector3d> probe_position = std::nullopt);
  [[nodiscard]] std::string name() const override { return "tracked_lamp"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

  [[nodiscard]] int frames_seen() const { return frames_seen_; }
  /// {"tag_id", "frames", "frames_seen", "frames_held", "frames_before_first_sighting",
  ///  "last_position", "last_axis"} for report.json, and with a probe "probe": {"position",
  ///  "frames_lamp_in_probe", "lights_taken_out", "taken_out_irradiance" and
  ///  "lamp_irradiance" (luminance at the probe, summed over those frames)}.
  [[nodiscard]] nlohmann::ordered_json summary() const;

 private:
  TrackedLamp lamp_;
  std::optional<Eigen::Vector3d> probe_position_;
  capture::TagLayout tag_alone_;  ///< the lamp's tag as a layout of its own frame
  std::optional<lights::Light> last_;
  int frames_ = 0;
  int frames_seen_ = 0;
  int frames_held_ = 0;
  int frames_lamp_in_probe_ = 0;
  int lights_taken_out_ = 0;
  double taken_out_irradiance_ = 0.0;  ///< luminance
  double lamp_irradiance_ = 0.0;       ///< luminance of the lamp's irradiance at the probe
  Read<capture::TagDetections> detections_;
  Read<DepthMap> depth_;
  Read<FrameInfo> frame_;
  Read<lights::LightSet> room_;
  Write<lights::LightSet> lights_;
};

}  // namespace relight::app
