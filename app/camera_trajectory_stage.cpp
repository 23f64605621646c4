#include "camera_trajectory_stage.h"

#include <cstdio>
#include <map>

#include "relight/capture/trajectory_error.h"
#include "relight/core/atomic_file.h"

namespace relight::app {

void CameraTrajectoryStage::declare(StageBuilder& builder) {
  pose_ = builder.read<CameraPose>("camera_pose");
  frame_ = builder.read<FrameInfo>("source_frame");
}

void CameraTrajectoryStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  entries_.push_back({frame.index, frame.timestamp, context.get(pose_), frame.camera_to_world});
}

void CameraTrajectoryStage::finish() {
  std::string text = "# camera poses of relight's tracking (camera to world), source " +
                     std::string(entries_.empty() ? "none" : to_string(entries_.front().pose.source)) +
                     "\n# timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (const auto& entry : entries_) {
    if (!entry.pose.valid) continue;
    const auto f = pose_to_tum(entry.pose.camera_to_world);
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n", entry.timestamp, f[0], f[1], f[2],
                  f[3], f[4], f[5], f[6]);
    text += line;
  }
  write_file_atomically(file_, text);
}

nlohmann::ordered_json CameraTrajectoryStage::summary() const {
  nlohmann::ordered_json json;
  json["source"] = entries_.empty() ? "none" : to_string(entries_.front().pose.source);
  int tracked = 0, held = 0, without = 0;
  std::map<std::string, int> reasons;
  nlohmann::ordered_json held_frames = nlohmann::ordered_json::array();
  std::vector<Pose> estimate, truth;
  double correction_max_cm = 0;
  for (const auto& entry : entries_) {
    if (!entry.pose.valid) {
      ++without;
    } else if (entry.pose.held) {
      ++held;
    } else {
      ++tracked;
    }
    if (!entry.pose.failure.empty()) {
      ++reasons[entry.pose.failure];
      if (held_frames.size() < 200) held_frames.push_back(entry.index);
    }
    correction_max_cm = std::max(correction_max_cm, entry.pose.correction_cm);
    if (entry.pose.valid && entry.reference) {
      estimate.push_back(entry.pose.camera_to_world);
      truth.push_back(*entry.reference);
    }
  }
  json["frames"] = entries_.size();
  json["frames_tracked"] = tracked;
  json["frames_holding_last_pose"] = held;
  json["frames_without_pose"] = without;
  json["flagged_frames"] = held_frames;
  json["failures"] = reasons;
  if (!entries_.empty() && entries_.front().pose.source == PoseSource::MarkerOdometry) {
    json["max_marker_correction_cm"] = correction_max_cm;
  }
  const bool compared = !entries_.empty() && entries_.front().pose.source != PoseSource::Sequence && estimate.size() >= 3;
  if (compared) {
    json["compared_with_sequence_poses"] = estimate.size();
    json["ate_cm"] = 100.0 * absolute_trajectory_error(estimate, truth);
    const RelativePoseError rpe = relative_pose_error(estimate, truth);
    json["rpe_deg"] = rpe.rotation_deg;
    json["rpe_cm"] = 100.0 * rpe.translation_m;
  }
  return json;
}

}  // namespace relight::app
