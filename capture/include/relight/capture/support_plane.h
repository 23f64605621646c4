#pragma once
// The dominant support plane of a depth frame (a table, the floor): RANSAC over a grid of depth
// samples, then a least-squares refit to the inliers. "Support" prefers planes that face up in
// the image (normal with a component against the camera's y, which points down), since a camera
// held upright sees the table below the horizon; without one it takes the largest plane.
//
// It gives the world frame of a run without ground truth or markers (z up along the plane's
// normal, origin below the first camera) and the surface that objects are placed on. The local
// plane of one pixel's surface (local_plane_at) is what `--place-at` stands an object on.
#include <cmath>
#include <optional>
#include <vector>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"

namespace relight::capture {

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, pointing to the camera's side
  double offset = 0;                                  ///< normal . p + offset = 0 on the plane
  int inliers = 0;                                    ///< depth samples within the tolerance
  double inlier_share = 0;                            ///< of the valid samples
  [[nodiscard]] double distance(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  /// A camera-frame point within `tolerance_m` of the plane, plus 1 % of its depth (Kinect noise
  /// grows with distance): what every fit here counts as an inlier.
  [[nodiscard]] bool holds(const Eigen::Vector3d& p, double tolerance_m) const {
    return std::abs(distance(p)) <= tolerance_m + 0.01 * p.z();
  }
  /// Where the camera ray through pixel (u, v) meets the plane (camera frame); nullopt when the
  /// ray runs parallel to it or meets it behind the camera.
  [[nodiscard]] std::optional<Eigen::Vector3d> ray_hit(const PinholeIntrinsics& intrinsics, double u, double v) const;
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

/// The up-facing planes in view, largest first (at most `max_planes`; each holding at least
/// min_inlier_share of the valid samples): the table and the floor, a shelf. RANSAC as above on
/// the samples the earlier planes left.
[[nodiscard]] std::vector<Plane> support_planes(const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                                int max_planes, const SupportPlaneOptions& options = {});

struct LocalPlaneOptions {
  /// Half-size of the pixel window fitted; 0: 1/64 of the image width, at least 4 pixels.
  int radius_px = 0;
  /// Samples whose depth differs from the centre's by more than this (plus 3 % of the depth)
  /// belong to another surface (an object's edge) and are left out before the fit.
  double depth_gate_m = 0.03;
  double tolerance_m = 0.01;  ///< inlier distance of the refits (plus 1 % of the depth)
  int min_samples = 20;       ///< fewer valid samples around the pixel: no plane
};

/// The plane of the surface seen around pixel (u, v), camera frame: a least-squares fit to the
/// valid depth in the window that lies near the centre's depth, refit twice to its inliers, so
/// one noisy normal or a neighbouring object does not tilt it. nullopt when the pixel (or the
/// middle of its window) has no valid depth or too few samples agree.
[[nodiscard]] std::optional<Plane> local_plane_at(const DepthMap& depth, const PinholeIntrinsics& intrinsics, double u,
                                                  double v, const LocalPlaneOptions& options = {});

/// Camera-to-world pose of a camera that sees `plane` (camera frame): world z along the plane's
/// normal, x along the camera's x projected onto the plane, origin at the camera's foot on it.
[[nodiscard]] Pose world_from_support_plane(const Plane& plane);

}  // namespace relight::capture
