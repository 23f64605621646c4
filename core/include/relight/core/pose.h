#pragma once
// Rigid camera poses. A Pose maps camera-frame points into the world frame (camera-to-world),
// the TUM groundtruth.txt convention: p_world = pose * p_camera.
#include <Eigen/Geometry>
#include <array>

namespace relight {

using Pose = Eigen::Isometry3d;

/// Timestamps are seconds (double), as in TUM files.
using Timestamp = double;

/// Build a pose from TUM fields tx ty tz qx qy qz qw (quaternion normalised here, at any scale
/// a double holds).
Pose pose_from_tum(const std::array<double, 7>& fields);
/// TUM fields tx ty tz qx qy qz qw of a pose (qw >= 0).
std::array<double, 7> pose_to_tum(const Pose& pose);
/// Interpolation between two poses: linear in translation, slerp in rotation, t in [0, 1].
Pose interpolate(const Pose& a, const Pose& b, double t);
/// Rotation angle (radians) of a.inverse() * b, for comparisons in tests and tools.
double rotation_distance(const Pose& a, const Pose& b);
/// The same angle in degrees.
double rotation_distance_degrees(const Pose& a, const Pose& b);

}  // namespace relight
