#include "marker_trajectory_stage.h"

#include <algorithm>

namespace relight::app {

nlohmann::ordered_json MarkerTrajectoryStage::summary() const {
  int fresh = 0, held = 0, compared = 0;
  double sum_cm = 0, max_cm = 0, sum_deg = 0, max_deg = 0;
  for (const auto& entry : entries()) {
    if (!entry.pose.valid) continue;
    entry.pose.held ? ++held : ++fresh;
    if (entry.pose.held || !entry.reference) continue;
    const double cm = 100.0 * (entry.pose.camera_to_world.translation() - entry.reference->translation()).norm();
    const double deg = rotation_distance_degrees(entry.pose.camera_to_world, *entry.reference);
    ++compared;
    sum_cm += cm;
    sum_deg += deg;
    max_cm = std::max(max_cm, cm);
    max_deg = std::max(max_deg, deg);
  }
  nlohmann::ordered_json json;
  json["frames"] = entries().size();
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
  const bool seen = std::any_of(entries().begin(), entries().end(), [](const Entry& e) { return e.pose.valid; });
  if (seen || entries().empty()) return "";
  return "relight: warning: no tag of the layout " + layout + " was seen in any of the " +
         std::to_string(entries().size()) + " frames, so there is no marker pose (wrong layout, tag family or ids?)\n";
}

}  // namespace relight::app
