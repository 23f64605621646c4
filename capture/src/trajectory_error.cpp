#include "relight/capture/trajectory_error.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "relight/core/error.h"

namespace relight::capture {

double absolute_trajectory_error(const std::vector<Pose>& estimate, const std::vector<Pose>& truth) {
  if (estimate.size() != truth.size()) throw LogicError("trajectory error: trajectories differ in length");
  if (estimate.empty()) return 0;
  Eigen::Matrix3Xd from(3, static_cast<Eigen::Index>(estimate.size()));
  Eigen::Matrix3Xd to(3, static_cast<Eigen::Index>(truth.size()));
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    from.col(static_cast<Eigen::Index>(i)) = estimate[i].translation();
    to.col(static_cast<Eigen::Index>(i)) = truth[i].translation();
  }
  // Horn's closed form through Umeyama's SVD, rigid (no scale), as TUM's evaluate_ate.
  const Eigen::Matrix4d alignment = estimate.size() >= 3 ? Eigen::umeyama(from, to, false)
                                                         : Eigen::Matrix4d::Identity();
  double squared = 0;
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    const Eigen::Vector3d aligned = alignment.topLeftCorner<3, 3>() * from.col(i) + alignment.topRightCorner<3, 1>();
    squared += (aligned - to.col(i)).squaredNorm();
  }
  return std::sqrt(squared / static_cast<double>(from.cols()));
}

RelativePoseError relative_pose_error(const std::vector<Pose>& estimate, const std::vector<Pose>& truth) {
  if (estimate.size() != truth.size()) throw LogicError("trajectory error: trajectories differ in length");
  RelativePoseError error;
  if (estimate.size() < 2) return error;
  double rotation = 0, translation = 0;
  for (std::size_t i = 0; i + 1 < estimate.size(); ++i) {
    const Pose true_step = truth[i].inverse() * truth[i + 1];
    const Pose estimated_step = estimate[i].inverse() * estimate[i + 1];
    const Pose difference = true_step.inverse() * estimated_step;
    const double angle = Eigen::AngleAxisd(difference.rotation()).angle() * 180.0 / std::numbers::pi;
    rotation += angle * angle;
    translation += difference.translation().squaredNorm();
  }
  const auto steps = static_cast<double>(estimate.size() - 1);
  error.rotation_deg = std::sqrt(rotation / steps);
  error.translation_m = std::sqrt(translation / steps);
  return error;
}

}  // namespace relight::capture
