#pragma once
// Sink stage: the tracked camera pose of every frame. At finish() it writes
// DIR/camera_trajectory.txt (TUM format, "timestamp tx ty tz qx qy qz qw", camera-to-world, one
// line per frame with a pose; held frames repeat the last good pose and are listed in the
// summary), whatever the pose source. summary() is report.json's "tracking": the source, the
// frames tracked and held (with why), and, when the sequence has poses of its own and they were
// not the source, the absolute trajectory error (after rigid alignment) and relative pose error
// against them.
// Reads: "camera_pose" (CameraPose), "source_frame" (FrameInfo: timestamp, the sequence's pose).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "relight/capture/camera_pose.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"

namespace relight::app {

class CameraTrajectoryStage final : public Stage {
 public:
  explicit CameraTrajectoryStage(std::filesystem::path file) : file_(std::move(file)) {}
  [[nodiscard]] std::string name() const override { return "camera_trajectory"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  void finish() override;

  [[nodiscard]] nlohmann::ordered_json summary() const;
  /// The last frame's pose state, for the progress line and the live view.
  [[nodiscard]] const CameraPose* last() const { return entries_.empty() ? nullptr : &entries_.back().pose; }

 private:
  struct Entry {
    std::int64_t index;
    Timestamp timestamp;
    CameraPose pose;
    std::optional<Pose> reference;
  };
  std::filesystem::path file_;
  std::vector<Entry> entries_;
  Read<CameraPose> pose_;
  Read<FrameInfo> frame_;
};

}  // namespace relight::app
