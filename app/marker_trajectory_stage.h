#pragma once
// Sink stage: collects the marker-based camera pose of every frame and, at finish(), writes
// DIR/marker_trajectory.txt in TUM format ("timestamp tx ty tz qx qy qz qw", camera-to-world;
// frames without any pose yet are skipped). When the sequence carries its own poses (TUM
// groundtruth.txt, or a synthetic sequence's exact poses) it also measures the marker pose
// against them; that comparison is meaningful when the tag layout and those poses share a world
// frame, as they do for `relight synth` sequences.
//
// Whatever the frames, the marker trajectory must have the sequence's shape: after a similarity
// alignment (Umeyama with scale) of the first sightings onto the sequence's poses the scale is
// 1 and the positions agree. A layout that contradicts the poses - a wrong tag size scales the
// marker trajectory, a tag placed elsewhere than the layout says bends it - stops the run with
// a relight::Error naming the layout and what is off.
// Reads: "marker_pose" (CameraPose), "source_frame" (FrameInfo: the sequence's own pose).
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pose_trajectory_stage.h"

namespace relight::app {

class MarkerTrajectoryStage final : public PoseTrajectoryStage {
 public:
  /// `layout`: how errors name the tag layout (its file).
  MarkerTrajectoryStage(std::filesystem::path file, std::string layout)
      : PoseTrajectoryStage(std::move(file), capture::kMarkerPose), layout_(std::move(layout)) {}
  [[nodiscard]] std::string name() const override { return "marker_trajectory"; }
  void run(StageContext& context) override;

  /// Frames, frames with a fresh / held pose, and the error against the sequence's poses.
  [[nodiscard]] nlohmann::ordered_json summary() const;
  /// One warning line, naming the layout, when frames ran but none saw one of its tags: most
  /// likely a wrong layout (family, ids) or no tag in view. The run itself goes on without a
  /// marker pose (the trajectory holds no pose). Empty otherwise.
  [[nodiscard]] std::string no_tag_warning(const std::string& layout) const;

 private:
  [[nodiscard]] std::string description() const override { return "camera poses from AprilTag markers (camera to world)"; }
  void check_against_sequence_poses();
  std::string layout_;
  bool checked_ = false;  ///< the check passed on enough sightings; not repeated
};

}  // namespace relight::app
