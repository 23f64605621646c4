#include "relight/capture/camera_tracking_stage.h"

#include <algorithm>

#include "relight/capture/buffers.h"
#include "relight/capture/support_plane.h"
#include "relight/core/buffers.h"
#include "relight/core/error.h"

namespace relight::capture {

namespace {

bool uses_marker(PoseSource source) { return source == PoseSource::Marker || source == PoseSource::MarkerOdometry; }

/// `from` moved towards `to` by at most max_m and max_deg.
Pose bounded_step(const Pose& from, const Pose& to, double max_m, double max_deg) {
  const double distance = (to.translation() - from.translation()).norm();
  const double angle = rotation_distance_degrees(from, to);
  double t = 1.0;
  if (distance > max_m) t = std::min(t, max_m / distance);
  if (angle > max_deg) t = std::min(t, max_deg / angle);
  return interpolate(from, to, t);
}

}  // namespace

CameraTrackingStage::CameraTrackingStage(const CameraTrackingOptions& options)
    : options_(options), source_(options.source), odometry_(options.odometry) {
  if (options_.source && uses_marker(*options_.source) && !options_.has_marker_layout) {
    throw Error(std::string("--pose ") + to_string(*options_.source) +
                " needs an AprilTag layout: give --markers FILE (a layout or a synthetic scene.json)");
  }
}

PoseSource CameraTrackingStage::resolve(const FrameInfo& first) const {
  if (source_) return *source_;
  if (first.camera_to_world) return PoseSource::Sequence;
  return options_.has_marker_layout ? PoseSource::MarkerOdometry : PoseSource::Odometry;
}

void CameraTrackingStage::declare(StageBuilder& builder) {
  source_frame_ = builder.read(kSourceFrame);
  if (!options_.source || *options_.source == PoseSource::Odometry || *options_.source == PoseSource::MarkerOdometry) {
    depth_ = builder.read(kDepth);
    color_ = builder.read(kColor);
  }
  if (options_.has_marker_layout && (!options_.source || uses_marker(*options_.source))) {
    marker_ = builder.read(kMarkerPose);
  }
  frame_ = builder.write(kFrame);
  pose_ = builder.write(kCameraPose);
}

CameraPose CameraTrackingStage::track_odometry(const FrameInfo& frame, const DepthMap& depth, const ColorImage& color,
                                               const CameraPose* marker) {
  const bool sighting = marker && marker->valid && !marker->held;
  CameraPose out;
  if (!odometry_.started()) {
    // The world frame: the marker layout's once a tag is seen (marker+odometry waits for it),
    // else the first camera levelled on its support plane.
    if (source_ == PoseSource::MarkerOdometry && !sighting) {
      out.failure = "waiting for a marker to fix the world frame";
      return out;
    }
    Pose first = Pose::Identity();
    if (sighting) {
      first = marker->camera_to_world;
    } else if (options_.level_with_support_plane) {
      if (const auto plane = dominant_support_plane(depth, frame.intrinsics)) first = world_from_support_plane(*plane);
    }
    odometry_.reset(first);
  }
  const OdometryResult result = odometry_.track(depth, color, frame.intrinsics, std::nullopt, frame.timestamp);
  if (!odometry_.started()) {  // the first frame had too little depth to place
    out.failure = result.quality.failure;
    return out;
  }
  out.valid = true;
  out.inlier_ratio = result.quality.inlier_ratio;
  out.keyframe = result.quality.keyframe;
  out.keyframes = static_cast<int>(odometry_.keyframe_count());
  out.keyframe_model_mb = static_cast<double>(odometry_.model_bytes()) / (1024.0 * 1024.0);
  out.keyframe_model_budget_mb = odometry_.options().model_budget_mb;
  out.camera_to_world = result.camera_to_world;
  out.held = !result.quality.tracked;
  out.failure = result.quality.failure;
  if (sighting) {
    out.tags_used = marker->tags_used;
    out.reprojection_rms_px = marker->reprojection_rms_px;
    // Lost: the tag re-anchors the tracker at once. Tracking: a bounded pull towards the marker.
    const Pose corrected = out.held ? marker->camera_to_world
                                    : bounded_step(out.camera_to_world,
                                                   interpolate(out.camera_to_world, marker->camera_to_world,
                                                               options_.correction_gain),
                                                   options_.max_correction_m, options_.max_correction_deg);
    out.correction_cm = 100.0 * (corrected.translation() - out.camera_to_world.translation()).norm();
    odometry_.correct(corrected);
    out.camera_to_world = corrected;
    out.held = false;
    out.failure.clear();
  }
  return out;
}

void CameraTrackingStage::run(StageContext& context) {
  const FrameInfo& source = context.get(source_frame_);
  if (!source_) source_ = resolve(source);
  CameraPose pose;
  switch (*source_) {
    case PoseSource::Sequence:
      if (source.camera_to_world) {
        pose.valid = true;
        pose.camera_to_world = *source.camera_to_world;
      } else if (!last_good_) {
        throw Error("--pose sequence: frame " + std::to_string(source.index) +
                    " has no pose of its own (no groundtruth.txt, or outside its time range); use --pose odometry "
                    "or marker+odometry");
      } else {
        pose.failure = "no sequence pose for this frame";
      }
      break;
    case PoseSource::Marker: pose = context.get(marker_); break;
    case PoseSource::Odometry:
    case PoseSource::MarkerOdometry:
      pose = track_odometry(source, context.get(depth_), context.get(color_),
                            *source_ == PoseSource::MarkerOdometry ? &context.get(marker_) : nullptr);
      break;
  }
  pose.source = *source_;
  if (pose.valid && !pose.held) {
    last_good_ = pose;
  } else if (last_good_) {
    // Hold the last good pose rather than render with one that jumped or is unknown.
    pose.camera_to_world = last_good_->camera_to_world;
    pose.valid = true;
    pose.held = true;
  }
  FrameInfo& frame = context.get(frame_);
  frame = source;
  frame.camera_to_world = pose.valid ? std::optional<Pose>(pose.camera_to_world) : std::nullopt;
  context.get(pose_) = std::move(pose);
}

}  // namespace relight::capture
