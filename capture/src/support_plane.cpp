#include "relight/capture/support_plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "relight/core/pixel.h"

namespace relight::capture {

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


// Least squares through the points `use` accepts (the smallest eigenvector of their scatter),
// the normal turned to the camera's side; nullopt for fewer than 3 points.
template <class Accept>
std::optional<Plane> fit_plane(const std::vector<Eigen::Vector3d>& points, Accept use) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& p : points) {
    if (use(p)) {
      mean += p;
      ++count;
    }
  }
  if (count < 3) return std::nullopt;
  mean /= count;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    if (use(p)) scatter += (p - mean) * (p - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Plane out;
  out.normal = solver.eigenvectors().col(0);
  out.offset = -out.normal.dot(mean);
  if (out.offset < 0) {  // the camera (origin) on the positive side
    out.normal = -out.normal;
    out.offset = -out.offset;
  }
  return out;
}

Plane refit(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double tolerance_m) {
  const auto fitted = fit_plane(points, [&](const Eigen::Vector3d& p) { return plane.holds(p, tolerance_m); });
  return fitted.value_or(plane);
}

int count_inliers(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double tolerance_m) {
  int count = 0;
  for (const auto& p : points) count += plane.holds(p, tolerance_m);
  return count;
}

}  // namespace

namespace {

std::vector<Eigen::Vector3d> depth_samples(const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                           const SupportPlaneOptions& options) {
  std::vector<Eigen::Vector3d> points;
  const int step = std::max(1, options.grid_step);
  for (int row = 0; row < depth.height(); row += step) {
    for (int col = 0; col < depth.width(); col += step) {
      const float z = depth(row, col);
      if (is_valid_depth(z)) points.push_back(intrinsics.unproject(col, row, z));
    }
  }
  return points;
}

// RANSAC: the up-facing plane with the most inliers, else (unless `support_only`) the plane with
// the most; refit twice. `total` is what inlier_share is a share of.
std::optional<Plane> ransac_plane(const std::vector<Eigen::Vector3d>& points, std::size_t total,
                                  const SupportPlaneOptions& options, bool support_only) {
  if (points.size() < 50) return std::nullopt;
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  std::optional<Plane> best_support, best_any;
  for (int it = 0; it < options.iterations; ++it) {
    auto candidate = plane_through(points[pick(rng)], points[pick(rng)], points[pick(rng)]);
    if (!candidate) continue;
    const int count = count_inliers(*candidate, points, options.tolerance_m);
    candidate->inliers = count;
    const bool support = -candidate->normal.y() >= options.min_up_component;
    if (support && (!best_support || count > best_support->inliers)) best_support = candidate;
    if (!best_any || count > best_any->inliers) best_any = candidate;
  }
  std::optional<Plane> chosen = best_support || support_only ? best_support : best_any;
  if (!chosen) return std::nullopt;
  Plane plane = refit(*chosen, points, options.tolerance_m);
  plane = refit(plane, points, options.tolerance_m);
  plane.inliers = count_inliers(plane, points, options.tolerance_m);
  plane.inlier_share = static_cast<double>(plane.inliers) / static_cast<double>(total);
  if (plane.inlier_share < options.min_inlier_share) return std::nullopt;
  return plane;
}

}  // namespace

std::optional<Plane> dominant_support_plane(const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                            const SupportPlaneOptions& options) {
  const auto points = depth_samples(depth, intrinsics, options);
  return ransac_plane(points, points.size(), options, false);
}

std::vector<Plane> support_planes(const DepthMap& depth, const PinholeIntrinsics& intrinsics, int max_planes,
                                  const SupportPlaneOptions& options) {
  auto points = depth_samples(depth, intrinsics, options);
  const std::size_t total = points.size();
  std::vector<Plane> planes;
  while (static_cast<int>(planes.size()) < max_planes) {
    auto plane = ransac_plane(points, total, options, true);
    if (!plane) break;
    std::erase_if(points, [&](const Eigen::Vector3d& p) { return plane->holds(p, options.tolerance_m); });
    planes.push_back(*plane);
  }
  return planes;
}

std::optional<Eigen::Vector3d> Plane::ray_hit(const PinholeIntrinsics& intrinsics, double u, double v) const {
  const Eigen::Vector3d ray = intrinsics.ray(u, v);
  const double along = normal.dot(ray);
  if (std::abs(along) < 1e-9) return std::nullopt;
  const double t = -offset / along;
  if (!(t > 0)) return std::nullopt;
  return t * ray;
}

std::optional<Plane> local_plane_at(const DepthMap& depth, const PinholeIntrinsics& intrinsics, double u, double v,
                                    const LocalPlaneOptions& options) {
  const int col = static_cast<int>(std::floor(u)), row = static_cast<int>(std::floor(v));
  if (col < 0 || row < 0 || col >= depth.width() || row >= depth.height()) return std::nullopt;
  const int radius = options.radius_px > 0 ? options.radius_px : std::max(4, depth.width() / 64);
  // The centre's depth: the median of the valid depth in the middle 5x5 (one hole or a flying
  // pixel does not decide which surface the pixel shows).
  std::vector<float> middle;
  for (int r = std::max(0, row - 2); r <= std::min(depth.height() - 1, row + 2); ++r)
    for (int c = std::max(0, col - 2); c <= std::min(depth.width() - 1, col + 2); ++c)
      if (is_valid_depth(depth(r, c))) middle.push_back(depth(r, c));
  if (middle.size() < 5) return std::nullopt;
  std::nth_element(middle.begin(), middle.begin() + static_cast<std::ptrdiff_t>(middle.size() / 2), middle.end());
  const double centre_z = middle[middle.size() / 2];
  const double gate = options.depth_gate_m + 0.03 * centre_z;
  std::vector<Eigen::Vector3d> points;
  for (int r = std::max(0, row - radius); r <= std::min(depth.height() - 1, row + radius); ++r) {
    for (int c = std::max(0, col - radius); c <= std::min(depth.width() - 1, col + radius); ++c) {
      const float z = depth(r, c);
      if (is_valid_depth(z) && std::abs(z - centre_z) <= gate) points.push_back(intrinsics.unproject(c, r, z));
    }
  }
  if (static_cast<int>(points.size()) < options.min_samples) return std::nullopt;
  auto plane = fit_plane(points, [](const Eigen::Vector3d&) { return true; });
  if (!plane) return std::nullopt;
  for (int pass = 0; pass < 2; ++pass) *plane = refit(*plane, points, options.tolerance_m);
  plane->inliers = count_inliers(*plane, points, options.tolerance_m);
  plane->inlier_share = static_cast<double>(plane->inliers) / static_cast<double>(points.size());
  if (plane->inliers < options.min_samples) return std::nullopt;
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

}  // namespace relight::capture
