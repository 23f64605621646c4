#pragma once
// Sink stage: the tracked camera pose of every frame. At finish() it writes
// DIR/camera_trajectory.txt (TUM format, "timestamp tx ty tz qx qy qz qw", camera-to-world, one
// line per frame with a pose; held frames repeat the last good pose and are listed in the
// summary), whatever the pose source. summary() is report.json's "tracking": the source, the
// frames tracked and held (with why), the odometry's keyframe model at the end (count and MB),
// and, when the sequence has poses of its own and they were
// not the source, the absolute trajectory error (after rigid alignment) and relative pose error
// against them.
// Reads: "camera_pose" (CameraPose), "source_frame" (FrameInfo: timestamp, the sequence's pose).
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pose_trajectory_stage.h"

namespace relight::app {

class CameraTrajectoryStage final : public PoseTrajectoryStage {
 public:
  explicit CameraTrajectoryStage(std::filesystem::path file)
      : PoseTrajectoryStage(std::move(file), capture::kCameraPose) {}
  [[nodiscard]] std::string name() const override { return "camera_trajectory"; }

  [[nodiscard]] nlohmann::ordered_json summary() const;
  /// The last frame's pose state, for the progress line and the live view.
  [[nodiscard]] const capture::CameraPose* last() const { return entries().empty() ? nullptr : &entries().back().pose; }

 private:
  [[nodiscard]] std::string description() const override;
};

}  // namespace relight::app
