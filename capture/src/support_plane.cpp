#include "relight/capture/support_plane.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <vector>

#include "relight/core/pixel.h"

namespace relight {

namespace {

std::optional<Plane> plane_through(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  Eigen::Vector3d normal = (b - a).cross(c - a);
  const double length = normal.norm();
  if (!(length > 1e-9)) return std::nullopt;
  normal /= length;
  Plane plane;
  plane.normal = normal;
  plane.offset = -normal.dot(a);
  if (plane.offset < 0) {  // the camera (origin) on the positive side
    plane.normal = -plane.normal;
    plane.offset = -plane.offset;
  }
  return plane;
}

bool inlier(const Plane& plane, const Eigen::Vector3d& p, const SupportPlaneOptions& options) {
  return std::abs(plane.distance(p)) <= options.tolerance_m + 0.01 * p.z();
}

// Least squares through the inliers (the smallest eigenvector of their scatter).
Plane refit(const Plane& plane, const std::vector<Eigen::Vector3d>& points, const SupportPlaneOptions& options) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& p : points) {
    if (inlier(plane, p, options)) {
      mean += p;
      ++count;
    }
  }
  if (count < 3) return plane;
  mean /= count;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    if (inlier(plane, p, options)) scatter += (p - mean) * (p - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Plane out = plane;
  out.normal = solver.eigenvectors().col(0);
  if (out.normal.dot(plane.normal) < 0) out.normal = -out.normal;
  out.offset = -out.normal.dot(mean);
  return out;
}

}  // namespace

std::optional<Plane> dominant_support_plane(const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                            const SupportPlaneOptions& options) {
  std::vector<Eigen::Vector3d> points;
  const int step = std::max(1, options.grid_step);
  for (int row = 0; row < depth.height(); row += step) {
    for (int col = 0; col < depth.width(); col += step) {
      const float z = depth(row, col);
      if (is_valid_depth(z)) points.push_back(intrinsics.unproject(col, row, z));
    }
  }
  if (points.size() < 50) return std::nullopt;
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  std::optional<Plane> best_support, best_any;
  for (int it = 0; it < options.iterations; ++it) {
    auto candidate = plane_through(points[pick(rng)], points[pick(rng)], points[pick(rng)]);
    if (!candidate) continue;
    int count = 0;
    for (const auto& p : points) count += inlier(*candidate, p, options);
    candidate->inliers = count;
    const bool support = -candidate->normal.y() >= options.min_up_component;
    if (support && (!best_support || count > best_support->inliers)) best_support = candidate;
    if (!best_any || count > best_any->inliers) best_any = candidate;
  }
  std::optional<Plane> chosen = best_support ? best_support : best_any;
  if (!chosen) return std::nullopt;
  Plane plane = refit(*chosen, points, options);
  plane = refit(plane, points, options);
  plane.inliers = 0;
  for (const auto& p : points) plane.inliers += inlier(plane, p, options);
  plane.inlier_share = static_cast<double>(plane.inliers) / static_cast<double>(points.size());
  if (plane.inlier_share < options.min_inlier_share) return std::nullopt;
  return plane;
}

Pose world_from_support_plane(const Plane& plane) {
  const Eigen::Vector3d z = plane.normal.normalized();
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z * z.x();  // camera x projected onto the plane
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitZ() - z * z.z();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_axes_in_camera;
  world_axes_in_camera << x, y, z;
  const Eigen::Vector3d foot = -plane.offset * z;  // the camera's foot on the plane
  // p_camera = A p_world + foot  =>  p_world = A^T (p_camera - foot)
  Pose camera_to_world = Pose::Identity();
  camera_to_world.linear() = world_axes_in_camera.transpose();
  camera_to_world.translation() = -world_axes_in_camera.transpose() * foot;
  return camera_to_world;
}

}  // namespace relight
