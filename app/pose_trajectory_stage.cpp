#include "pose_trajectory_stage.h"

#include <cstdio>

#include "relight/core/atomic_file.h"
#include "relight/core/buffers.h"

namespace relight::app {

void PoseTrajectoryStage::declare(StageBuilder& builder) {
  pose_ = builder.read(pose_buffer_);
  frame_ = builder.read(kSourceFrame);
}

void PoseTrajectoryStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  entries_.push_back({frame.index, frame.timestamp, context.get(pose_), frame.camera_to_world});
}

void PoseTrajectoryStage::finish() {
  std::string text = "# " + description() + "\n# timestamp tx ty tz qx qy qz qw\n";
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

}  // namespace relight::app
