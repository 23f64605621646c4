#pragma once
// Sink stage: collects the marker-based camera pose of every frame and, at finish(), writes
// DIR/marker_trajectory.txt in TUM format ("timestamp tx ty tz qx qy qz qw", camera-to-world;
// frames without any pose yet are skipped). When the sequence carries its own poses (TUM
// groundtruth.txt, or a synthetic sequence's exact poses) it also measures the marker pose
// against them; that comparison is meaningful when the tag layout and those poses share a world
// frame, as they do for `relight synth` sequences.
// Reads: "marker_pose" (CameraPose), "source_frame" (FrameInfo: the sequence's own pose).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "relight/capture/marker_pose.h"
#include "relight/core/frame_graph.h"

namespace relight::app {

class MarkerTrajectoryStage final : public Stage {
 public:
  explicit MarkerTrajectoryStage(std::filesystem::path file) : file_(std::move(file)) {}
  [[nodiscard]] std::string name() const override { return "marker_trajectory"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  void finish() override;

  /// Frames, frames with a fresh / held pose, and the error against the sequence's poses.
  [[nodiscard]] nlohmann::ordered_json summary() const;
  /// One warning line, naming the layout, when frames ran but none saw one of its tags: most
  /// likely a wrong layout (family, ids) or no tag in view. The run itself goes on without a
  /// marker pose (the trajectory holds no pose). Empty otherwise.
  [[nodiscard]] std::string no_tag_warning(const std::string& layout) const;

 private:
  struct Entry {
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
