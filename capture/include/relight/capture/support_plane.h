#pragma once
// The dominant support plane of a depth frame (a table, the floor): RANSAC over a grid of depth
// samples, then a least-squares refit to the inliers. "Support" prefers planes that face up in
// the image (normal with a component against the camera's y, which points down), since a camera
// held upright sees the table below the horizon; without one it takes the largest plane.
//
// It gives the world frame of a run without ground truth or markers (z up along the plane's
// normal, origin below the first camera) and the surface that objects are placed on.
#include <optional>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"

namespace relight {

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, pointing to the camera's side
  double offset = 0;                                  ///< normal . p + offset = 0 on the plane
  int inliers = 0;                                    ///< depth samples within the tolerance
  double inlier_share = 0;                            ///< of the valid samples
  [[nodiscard]] double distance(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
};

struct SupportPlaneOptions {
  int grid_step = 4;               ///< sample every 4th pixel in both directions
  int iterations = 300;
  double tolerance_m = 0.015;      ///< inlier distance (plus 1 % of the depth)
  double min_inlier_share = 0.08;  ///< smaller planes are not a support
  /// A support plane faces up: normal . (0, -1, 0) at least this (about 45 degrees).
  double min_up_component = 0.7;
  unsigned seed = 1;               ///< RANSAC is deterministic for a given seed
};

/// The plane in the camera frame; nullopt when no plane holds min_inlier_share of the samples.
[[nodiscard]] std::optional<Plane> dominant_support_plane(const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                                          const SupportPlaneOptions& options = {});

/// Camera-to-world pose of a camera that sees `plane` (camera frame): world z along the plane's
/// normal, x along the camera's x projected onto the plane, origin at the camera's foot on it.
[[nodiscard]] Pose world_from_support_plane(const Plane& plane);

}  // namespace relight
