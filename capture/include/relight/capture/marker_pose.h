#pragma once
// Camera pose from AprilTag markers of a known layout: the detected corners and the layout's
// world corners give a Perspective-n-Point problem solved with OpenCV's solvePnP. All corners of
// all known tags are used together: IPPE (Collins & Bartoli 2014) when they are coplanar (one
// tag, or several on the table), the iterative Levenberg-Marquardt solver otherwise, refined
// with solvePnPRefineLM in both cases. A small tag far away pins the rotation well but the
// distance poorly (a corner error of 0.3 px moves a 16 cm tag at 2 m by ~1.5 cm along the
// ray); refine_with_depth() corrects that distance from the depth map: the median ratio of
// measured to predicted depth over the tag's face scales the camera-to-tag vector. A single tag
// seen nearly head-on pins its tilt poorly too; within kMarkerHeadOnDegrees of head-on the stage
// takes the tilt from the depth of the tag's face first (refine_tilt_with_depth).
//
// Stage MarkerPoseStage
//   reads:  "tag_detections" (TagDetections, tag_detection_stage.h), "depth" (DepthMap, for the
//           refinement), "frame" (FrameInfo: intrinsics)
//   writes: "marker_pose" (CameraPose): camera-to-world; when no known tag is visible the last
//           pose is held and flagged (held = true), before the first detection valid = false.
//   The frame buffer it reads is "frame" by default; in replay/live, where the camera tracking
//   stage (camera_tracking_stage.h) writes "frame", it reads the source's "source_frame".
#include <optional>
#include <vector>

#include "relight/capture/camera_pose.h"
#include "relight/capture/tag_detection_stage.h"
#include "relight/capture/tag_detector.h"
#include "relight/capture/tag_layout.h"
#include "relight/core/buffers.h"
#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/pose.h"
#include "relight/core/rgbd_frame.h"

namespace relight::capture {

struct MarkerPose {
  Pose camera_to_world = Pose::Identity();
  int tags_used = 0;
  double reprojection_rms_px = 0;
};

/// Pose from the detections of tags that the layout knows; nullopt when none is known.
[[nodiscard]] std::optional<MarkerPose> estimate_camera_pose(const std::vector<TagDetection>& detections,
                                                            const TagLayout& layout,
                                                            const PinholeIntrinsics& intrinsics);

/// Tilt refinement from registered depth for one tag: a small tag seen nearly head-on pins its
/// in-plane rotation well but its tilt poorly (its corners move little as it tilts), while the
/// depth of its face gives the face's plane. The points measured inside the tag (inset from its
/// edges) are fitted with a plane (least squares, then again without the points more than three
/// median deviations off it), and the pose is turned about the tag's centre by the smallest
/// rotation that takes its face normal onto the plane's. Returns the pose unchanged when the
/// layout does not know exactly one detected tag, the tag is seen more than
/// `max_view_angle_degrees` off head-on (its face normal against the ray to its centre; seen
/// obliquely, the corners pin the tilt themselves), fewer than `min_points` depth samples fall
/// on it, or the two normals are more than 30 degrees apart (the depth is not the tag's).
[[nodiscard]] MarkerPose refine_tilt_with_depth(const MarkerPose& pose, const std::vector<TagDetection>& detections,
                                                const TagLayout& layout, const PinholeIntrinsics& intrinsics,
                                                const DepthMap& depth, double max_view_angle_degrees = 90.0,
                                                int min_points = 30);

/// The camera's marker pose refines a single tag's tilt from depth within this angle of head-on.
inline constexpr double kMarkerHeadOnDegrees = 25.0;

/// The pose from colour and depth, as MarkerPoseStage and a tracked lamp find it:
/// estimate_camera_pose, then refine_tilt_with_depth within `head_on_degrees` of head-on, then
/// refine_with_depth. None when no tag of the layout was detected.
[[nodiscard]] std::optional<MarkerPose> estimate_camera_pose(const std::vector<TagDetection>& detections,
                                                             const TagLayout& layout,
                                                             const PinholeIntrinsics& intrinsics, const DepthMap& depth,
                                                             double head_on_degrees = kMarkerHeadOnDegrees);

/// Distance refinement from registered depth (see above); returns the pose unchanged when fewer
/// than 10 valid depth samples fall on the tags.
[[nodiscard]] MarkerPose refine_with_depth(const MarkerPose& pose, const std::vector<TagDetection>& detections,
                                           const TagLayout& layout, const PinholeIntrinsics& intrinsics,
                                           const DepthMap& depth);

class MarkerPoseStage final : public Stage {
 public:
  explicit MarkerPoseStage(TagLayout layout, BufferName<FrameInfo> frame_buffer = kFrame)
      : layout_(std::move(layout)), frame_buffer_(frame_buffer) {}
  [[nodiscard]] std::string name() const override { return "marker_pose"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  TagLayout layout_;
  BufferName<FrameInfo> frame_buffer_;
  std::optional<MarkerPose> last_;
  Read<TagDetections> detections_;
  Read<DepthMap> depth_;
  Read<FrameInfo> frame_;
  Write<CameraPose> pose_;
};

}  // namespace relight::capture
