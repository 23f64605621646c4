#pragma once
// Sink stage base of the trajectory files: collects one CameraPose buffer of every frame with
// the source frame's timestamp and the sequence's own pose (for comparisons), and at finish()
// writes the frames that have a pose as a TUM trajectory ("timestamp tx ty tz qx qy qz qw",
// camera-to-world) under one comment line that says what the poses are.
// Reads: the CameraPose buffer given, "source_frame" (FrameInfo: timestamp, the sequence's pose).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "relight/capture/buffers.h"
#include "relight/capture/camera_pose.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"

namespace relight::app {

class PoseTrajectoryStage : public Stage {
 public:
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  void finish() override;

 protected:
  PoseTrajectoryStage(std::filesystem::path file, BufferName<capture::CameraPose> pose_buffer)
      : file_(std::move(file)), pose_buffer_(pose_buffer) {}
  struct Entry {
    std::int64_t index;
    Timestamp timestamp;
    capture::CameraPose pose;
    std::optional<Pose> reference;  ///< the sequence's own pose, when it has one
  };
  [[nodiscard]] const std::vector<Entry>& entries() const { return entries_; }
  /// The file's first comment line (without "# ").
  [[nodiscard]] virtual std::string description() const = 0;

 private:
  std::filesystem::path file_;
  BufferName<capture::CameraPose> pose_buffer_;
  std::vector<Entry> entries_;
  Read<capture::CameraPose> pose_;
  Read<FrameInfo> frame_;
};

}  // namespace relight::app
