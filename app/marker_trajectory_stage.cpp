#include "marker_trajectory_stage.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>

#include "relight/core/error.h"

namespace relight::app {

namespace {

// Sightings before the check, and after which it is not repeated; the sequence's camera must
// have moved this far for a scale to mean anything.
constexpr int kMinSightings = 8;
constexpr int kMaxSightings = 64;
constexpr double kMinSpreadM = 0.05;
constexpr double kMaxScaleRatio = 1.25;  // the aligned scale in [1/1.25, 1.25]
constexpr double kMaxResidualM = 0.05;   // RMS after the alignment (a marker pose is good to ~1 cm)

}  // namespace

void MarkerTrajectoryStage::run(StageContext& context) {
  PoseTrajectoryStage::run(context);
  if (!checked_) check_against_sequence_poses();
}

void MarkerTrajectoryStage::check_against_sequence_poses() {
  std::vector<Eigen::Vector3d> marker, sequence;
  for (const auto& entry : entries()) {
    if (!entry.pose.valid || entry.pose.held || !entry.reference) continue;
    marker.push_back(entry.pose.camera_to_world.translation());
    sequence.push_back(entry.reference->translation());
  }
  const auto n = static_cast<int>(marker.size());
  if (n < kMinSightings || (n % 4 != 0 && n < kMaxSightings)) return;
  Eigen::Matrix3Xd from(3, n), to(3, n);
  for (int i = 0; i < n; ++i) {
    from.col(i) = marker[static_cast<std::size_t>(i)];
    to.col(i) = sequence[static_cast<std::size_t>(i)];
  }
  const Eigen::Vector3d mean = to.rowwise().mean();
  const double spread = (to.colwise() - mean).colwise().norm().maxCoeff();
  if (spread < kMinSpreadM) {
    if (n >= kMaxSightings) checked_ = true;  // a camera that never moved: nothing to compare
    return;
  }
  const Eigen::Matrix4d alignment = Eigen::umeyama(from, to, true);
  const double scale = alignment.block<3, 1>(0, 0).norm();
  const Eigen::Matrix3Xd aligned = (alignment.block<3, 3>(0, 0) * from).colwise() + alignment.block<3, 1>(0, 3);
  const double rms = std::sqrt((aligned - to).colwise().squaredNorm().mean());
  char numbers[160];
  if (scale > kMaxScaleRatio || scale < 1.0 / kMaxScaleRatio) {
    std::snprintf(numbers, sizeof numbers, "%.2f times", 1.0 / scale);
    throw Error("the tag layout " + layout_ + " contradicts the sequence's camera poses: over the first " +
                std::to_string(n) + " sightings the marker trajectory is " + numbers +
                " the size of the sequence's (a wrong tag size in the layout, or poses in other units?)");
  }
  if (rms > kMaxResidualM) {
    std::snprintf(numbers, sizeof numbers, "%.1f cm", 100.0 * rms);
    throw Error("the tag layout " + layout_ + " contradicts the sequence's camera poses: over the first " +
                std::to_string(n) + " sightings the marker poses are " + numbers +
                " (RMS) off the sequence's after aligning them (are the tags where the layout says?)");
  }
  if (n >= kMaxSightings) checked_ = true;
}

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
