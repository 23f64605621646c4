#include "relight/core/pose.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace relight {

Pose pose_from_tum(const std::array<double, 7>& f) {
  Eigen::Quaterniond q(f[6], f[3], f[4], f[5]);  // Eigen's constructor order is (w, x, y, z)
  // Scale by the largest component first: the squared norm of components around 1e155 or more
  // overflows to infinity, and normalising by it left a zero quaternion (the identity rotation).
  const double largest = q.coeffs().cwiseAbs().maxCoeff();
  if (largest > 0.0 && std::isfinite(largest)) q.coeffs() /= largest;
  q.normalize();
  Pose pose = Pose::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Eigen::Vector3d(f[0], f[1], f[2]);
  return pose;
}

std::array<double, 7> pose_to_tum(const Pose& pose) {
  Eigen::Quaterniond q(pose.linear());
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d t = pose.translation();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

Pose interpolate(const Pose& a, const Pose& b, double t) {
  const Eigen::Quaterniond qa(a.linear());
  const Eigen::Quaterniond qb(b.linear());
  Pose pose = Pose::Identity();
  pose.linear() = qa.slerp(t, qb).normalized().toRotationMatrix();
  pose.translation() = (1.0 - t) * a.translation() + t * b.translation();
  return pose;
}

double rotation_distance(const Pose& a, const Pose& b) {
  const Eigen::Matrix3d relative = a.linear().transpose() * b.linear();
  const double cosine = std::clamp((relative.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cosine);
}

double rotation_distance_degrees(const Pose& a, const Pose& b) { return rotation_distance(a, b) * 180.0 / std::numbers::pi; }

}  // namespace relight
