#pragma once
// The one camera pose of a frame, whatever its source (`--pose`): the stage every pose reader
// depends on. It rewrites the source's frame info with the tracked pose, so that method 1's
// reprojection, method 2's warp, the BRDF's light moves, DIR and the temporal filters all read
// the same pose through "frame".
//
// Stage CameraTrackingStage
//   reads:  "source_frame" (FrameInfo of the source), "depth" (DepthMap), "color" (ColorImage),
//           "marker_pose" (CameraPose of MarkerPoseStage; marker sources only)
//   writes: "frame" (FrameInfo: the source's, camera_to_world = the tracked pose),
//           "camera_pose" (CameraPose: the pose, its source and its state)
//
// Sources (PoseSource):
//   Sequence:  the source's own pose; a sequence without poses is an error at the first frame.
//   Marker:    the marker pose; before the first sighting the pose is invalid (identity).
//   Odometry:  RgbdOdometry (rgbd_odometry.h). The world is the first frame's camera with z up
//              along the dominant support plane (support_plane.h), origin at the camera's foot
//              on it; without a plane, the first camera.
//   MarkerOdometry: odometry between sightings; the world is the marker layout's frame. The
//              first sighting places the odometry in that frame; later sightings pull the pose
//              towards the marker pose by `correction_gain` of the difference, at most
//              `max_correction_m` / `max_correction_deg` a frame (no visible jump; a marker pose is itself only good to about a centimetre),
//              and the keyframes move with it. While odometry is lost a sighting re-anchors it.
// Failure (odometry lost, a tag out of view in Marker mode, a frame without a sequence pose)
// holds the last good pose and says why (CameraPose::held, failure); nothing renders with a
// pose that jumped.
#include <optional>

#include "relight/capture/camera_pose.h"
#include "relight/capture/rgbd_odometry.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"

namespace relight::capture {

struct CameraTrackingOptions {
  /// nullopt: auto, decided at the first frame: the sequence's own poses when it has them, else
  /// marker+odometry when there is a marker layout (has_marker_layout), else odometry.
  std::optional<PoseSource> source;
  bool has_marker_layout = false;  ///< a MarkerPoseStage writes "marker_pose" (needed by marker sources)
  RgbdOdometryOptions odometry;
  /// marker+odometry: the share of the odometry-to-marker difference taken per sighting (a
  /// marker pose is only good to about a centimetre; odometry is smoother frame to frame, so
  /// the correction averages the marker over ~1/gain sightings), bounded per frame by:
  double correction_gain = 0.1;
  double max_correction_m = 0.004;   ///< marker+odometry: per frame
  double max_correction_deg = 0.3;   ///< marker+odometry: per frame
  bool level_with_support_plane = true;  ///< odometry: z up from the first frame's plane
};

class CameraTrackingStage final : public Stage {
 public:
  explicit CameraTrackingStage(const CameraTrackingOptions& options);
  [[nodiscard]] std::string name() const override { return "camera_tracking"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  CameraPose track_odometry(const FrameInfo& frame, const DepthMap& depth, const ColorImage& color,
                            const CameraPose* marker);
  [[nodiscard]] PoseSource resolve(const FrameInfo& first) const;
  CameraTrackingOptions options_;
  std::optional<PoseSource> source_;  ///< options_.source, or what auto chose at the first frame
  RgbdOdometry odometry_;
  std::optional<CameraPose> last_good_;
  Read<FrameInfo> source_frame_;
  Read<DepthMap> depth_;
  Read<ColorImage> color_;
  Read<CameraPose> marker_;
  Write<FrameInfo> frame_;
  Write<CameraPose> pose_;
};

}  // namespace relight::capture
