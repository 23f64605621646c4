#include "marker_trajectory_stage.h"

#include <algorithm>
#include <cstdio>
#include <numbers>

#include "relight/core/atomic_file.h"

namespace relight::app {

void MarkerTrajectoryStage::declare(StageBuilder& builder) {
  pose_ = builder.read<CameraPose>("marker_pose");
  frame_ = builder.read<FrameInfo>("source_frame");
}

void MarkerTrajectoryStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  entries_.push_back({frame.timestamp, context.get(pose_), frame.camera_to_world});
}

void MarkerTrajectoryStage::finish() {
  std::string text = "# camera poses from AprilTag markers (camera to world)\n# timestamp tx ty tz qx qy qz qw\n";
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

nlohmann::ordered_json MarkerTrajectoryStage::summary() const {
  int fresh = 0, held = 0, compared = 0;
  double sum_cm = 0, max_cm = 0, sum_deg = 0, max_deg = 0;
  for (const auto& entry : entries_) {
    if (!entry.pose.valid) continue;
    entry.pose.held ? ++held : ++fresh;
    if (entry.pose.held || !entry.reference) continue;
    const double cm = 100.0 * (entry.pose.camera_to_world.translation() - entry.reference->translation()).norm();
    const double deg = rotation_distance(entry.pose.camera_to_world, *entry.reference) * 180.0 / std::numbers::pi;
    ++compared;
    sum_cm += cm;
    sum_deg += deg;
    max_cm = std::max(max_cm, cm);
    max_deg = std::max(max_deg, deg);
  }
  nlohmann::ordered_json json;
  json["frames"] = entries_.size();
  json["frames_with_marker_pose"] = fresh;
  json["frames_holding_last_pose"] = held;
  if (compared > 0) {
    json["compared_with_sequence_poses"] = compared;
    json["mean_error_cm"] = sum_cm / compared;
    json["max_error_cm"] = max_cm;
    json["mean_error_deg"] = sum_deg / compared;
    json["max_error_deg"] = max_deg;
  }
  return json;
}

std::string MarkerTrajectoryStage::no_tag_warning(const std::string& layout) const {
  const bool seen = std::any_of(entries_.begin(), entries_.end(), [](const Entry& e) { return e.pose.valid; });
  if (seen || entries_.empty()) return "";
  return "relight: warning: no tag of the layout " + layout + " was seen in any of the " +
         std::to_string(entries_.size()) + " frames, so there is no marker pose (wrong layout, tag family or ids?)\n";
}

}  // namespace relight::app
