#include "camera_trajectory_stage.h"

#include <map>

#include "relight/capture/trajectory_error.h"

namespace relight::app {

std::string CameraTrajectoryStage::description() const {
  return "camera poses of relight's tracking (camera to world), source " +
         std::string(entries().empty() ? "none" : to_string(entries().front().pose.source));
}

nlohmann::ordered_json CameraTrajectoryStage::summary() const {
  const auto& recorded = entries();
  nlohmann::ordered_json json;
  json["source"] = recorded.empty() ? "none" : to_string(recorded.front().pose.source);
  int tracked = 0, held = 0, without = 0;
  std::map<std::string, int> reasons;
  nlohmann::ordered_json held_frames = nlohmann::ordered_json::array();
  std::vector<Pose> estimate, truth;
  double correction_max_cm = 0;
  for (const auto& entry : recorded) {
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
  json["frames"] = recorded.size();
  json["frames_tracked"] = tracked;
  json["frames_holding_last_pose"] = held;
  json["frames_without_pose"] = without;
  json["flagged_frames"] = held_frames;
  json["failures"] = reasons;
  if (!recorded.empty() && recorded.front().pose.source == capture::PoseSource::MarkerOdometry) {
    json["max_marker_correction_cm"] = correction_max_cm;
  }
  if (!recorded.empty() && recorded.back().pose.keyframes > 0) {  // the odometry's model at the end
    json["keyframes"] = recorded.back().pose.keyframes;
    json["keyframe_model_mb"] = recorded.back().pose.keyframe_model_mb;
    json["keyframe_model_budget_mb"] = recorded.back().pose.keyframe_model_budget_mb;
  }
  const bool compared =
      !recorded.empty() && recorded.front().pose.source != capture::PoseSource::Sequence && estimate.size() >= 3;
  if (compared) {
    json["compared_with_sequence_poses"] = estimate.size();
    json["ate_cm"] = 100.0 * capture::absolute_trajectory_error(estimate, truth);
    const capture::RelativePoseError rpe = capture::relative_pose_error(estimate, truth);
    json["rpe_deg"] = rpe.rotation_deg;
    json["rpe_cm"] = 100.0 * rpe.translation_m;
  }
  return json;
}

}  // namespace relight::app
