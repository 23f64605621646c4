#pragma once
// The camera pose of one frame as the graph carries it ("camera_pose", and the marker stage's
// "marker_pose"): where the camera is, where that came from, and whether it can be trusted.
#include <array>
#include <optional>
#include <string>

#include "relight/core/named_values.h"
#include "relight/core/pose.h"

namespace relight::capture {

/// Where a frame's camera pose comes from (`--pose`).
enum class PoseSource {
  Sequence,        ///< the recording's own poses (TUM groundtruth.txt, synthetic truth)
  Marker,          ///< AprilTags of a known layout; the world is the layout's frame
  Odometry,        ///< markerless RGB-D tracking; the world is the first frame's, z up
  MarkerOdometry,  ///< odometry, corrected towards the marker pose whenever a tag is seen
};
/// `--pose`'s values: "auto" (nullopt: decided at the first frame, camera_tracking_stage.h) and
/// every source.
inline constexpr std::array<NamedValue<std::optional<PoseSource>>, 5> kPoseSourceNames{
    {{"auto", std::nullopt},
     {"sequence", PoseSource::Sequence},
     {"marker", PoseSource::Marker},
     {"odometry", PoseSource::Odometry},
     {"marker+odometry", PoseSource::MarkerOdometry}}};
[[nodiscard]] inline const char* to_string(PoseSource source) {
  return name_of(kPoseSourceNames, std::optional<PoseSource>(source));
}

struct CameraPose {
  Pose camera_to_world = Pose::Identity();
  bool valid = false;  ///< false until a first pose is known
  bool held = false;   ///< this frame has no pose of its own: the last good one is repeated
  /// Tracking failed on this frame (held == true): the reason, for report.json and the view.
  std::string failure;
  PoseSource source = PoseSource::Sequence;
  // Marker pose
  int tags_used = 0;
  double reprojection_rms_px = 0;
  // Odometry
  double inlier_ratio = 0;
  int keyframe = -1;
  int keyframes = 0;             ///< stored in the tracker's model after this frame
  double keyframe_model_mb = 0;  ///< their memory (RgbdOdometryOptions::model_budget_mb bounds it)
  double keyframe_model_budget_mb = 0;  ///< that bound, so reports and scripts need no second copy of it
  double correction_cm = 0;  ///< marker+odometry: how far the marker moved the pose this frame
  static constexpr const char* type_name = "CameraPose";
};

}  // namespace relight::capture
