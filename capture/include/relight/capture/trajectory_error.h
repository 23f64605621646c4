#pragma once
// Trajectory accuracy as the TUM RGB-D benchmark measures it (Sturm et al. 2012): absolute
// trajectory error after a rigid alignment, and relative pose error between consecutive frames.
#include <vector>

#include "relight/core/pose.h"

namespace relight::capture {

/// Absolute trajectory error: RMSE (metres) of the positions after the rigid alignment
/// (Horn / Umeyama, no scale) of `estimate` onto `truth`; the vectors are paired by index.
[[nodiscard]] double absolute_trajectory_error(const std::vector<Pose>& estimate, const std::vector<Pose>& truth);
/// Relative pose error over consecutive frames: RMSE of the rotation angle (degrees) of
/// (truth_i^-1 truth_i+1)^-1 (estimate_i^-1 estimate_i+1), and of its translation (metres).
struct RelativePoseError {
  double rotation_deg = 0;
  double translation_m = 0;
};
[[nodiscard]] RelativePoseError relative_pose_error(const std::vector<Pose>& estimate, const std::vector<Pose>& truth);

}  // namespace relight::capture
