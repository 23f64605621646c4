#include "relight/capture/marker_pose.h"
#include "relight/capture/buffers.h"
#include "relight/core/buffers.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace relight::capture {

namespace {

bool coplanar(const std::vector<cv::Point3d>& points) {
  if (points.size() < 4) return true;
  Eigen::MatrixXd centred(3, static_cast<Eigen::Index>(points.size()));
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += Eigen::Vector3d(p.x, p.y, p.z);
  mean /= static_cast<double>(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    centred.col(static_cast<Eigen::Index>(i)) = Eigen::Vector3d(points[i].x, points[i].y, points[i].z) - mean;
  }
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::MatrixXd>(centred).singularValues();
  return singular(2) < 1e-6 * std::max(1.0, singular(0));
}

double reprojection_rms(const std::vector<cv::Point3d>& world, const std::vector<cv::Point2d>& image,
                        const cv::Mat& rvec, const cv::Mat& tvec, const cv::Matx33d& k) {
  std::vector<cv::Point2d> projected;
  cv::projectPoints(world, rvec, tvec, k, cv::noArray(), projected);
  double sum = 0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const cv::Point2d d = projected[i] - image[i];
    sum += d.dot(d);
  }
  return std::sqrt(sum / static_cast<double>(image.size()));
}

}  // namespace

std::optional<MarkerPose> estimate_camera_pose(const std::vector<TagDetection>& detections, const TagLayout& layout,
                                               const PinholeIntrinsics& intrinsics) {
  std::vector<cv::Point3d> world;
  std::vector<cv::Point2d> image;
  int tags_used = 0;
  for (const auto& detection : detections) {
    const TagLayout::Tag* tag = layout.find(detection.id);
    if (!tag) continue;
    ++tags_used;
    for (std::size_t k = 0; k < 4; ++k) {
      world.emplace_back(tag->corners_world[k].x(), tag->corners_world[k].y(), tag->corners_world[k].z());
      image.emplace_back(detection.corners[k].x(), detection.corners[k].y());
    }
  }
  if (tags_used == 0) return std::nullopt;

  const cv::Matx33d k(intrinsics.fx, 0, intrinsics.cx, 0, intrinsics.fy, intrinsics.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  const int method = coplanar(world) ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_ITERATIVE;
  if (!cv::solvePnP(world, image, k, cv::noArray(), rvec, tvec, false, method)) return std::nullopt;
  cv::solvePnPRefineLM(world, image, k, cv::noArray(), rvec, tvec);

  // solvePnP gives world-to-camera; the pose slot holds camera-to-world.
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  Pose world_to_camera = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) world_to_camera.linear()(r, c) = rotation(r, c);
    world_to_camera.translation()(r) = tvec.at<double>(r);
  }
  MarkerPose pose;
  pose.camera_to_world = world_to_camera.inverse();
  pose.tags_used = tags_used;
  pose.reprojection_rms_px = reprojection_rms(world, image, rvec, tvec, k);
  return pose;
}

namespace {

/// The share of a tag's edge left out on each side where its face's depth is read: near the
/// edges the depth is unreliable (mixed with what lies behind).
constexpr double kFaceInset = 0.15;

// Depth ratios measured / predicted at a grid of points on one tag's face (inset from the edges,
// where depth is unreliable).
void collect_depth_ratios(const TagLayout::Tag& tag, const Pose& world_to_camera, const PinholeIntrinsics& k,
                          const DepthMap& depth, std::vector<double>& ratios) {
  constexpr int kGrid = 9;
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      const double span = 1.0 - 2.0 * kFaceInset;
      const double a = kFaceInset + span * i / (kGrid - 1), b = kFaceInset + span * j / (kGrid - 1);
      const Eigen::Vector3d on_tag = tag.corners_world[0] + a * (tag.corners_world[1] - tag.corners_world[0]) +
                                     b * (tag.corners_world[3] - tag.corners_world[0]);
      const Eigen::Vector3d camera = world_to_camera * on_tag;
      if (camera.z() <= 0) continue;
      const Eigen::Vector2d pixel = k.project(camera);
      const int col = static_cast<int>(std::lround(pixel.x())), row = static_cast<int>(std::lround(pixel.y()));
      if (!depth.in_bounds(row, col) || !is_valid_depth(depth(row, col))) continue;
      // The predicted depth at the rounded pixel: intersect its ray with the tag plane.
      const Eigen::Vector3d normal = world_to_camera.linear() * tag.normal();
      const Eigen::Vector3d ray = k.ray(col, row);
      const double denominator = normal.dot(ray);
      if (std::abs(denominator) < 1e-9) continue;
      const double predicted = normal.dot(camera) / denominator;  // z of the ray point (ray.z() == 1)
      if (predicted > 0) ratios.push_back(depth(row, col) / predicted);
    }
  }
}

}  // namespace

MarkerPose refine_with_depth(const MarkerPose& pose, const std::vector<TagDetection>& detections,
                             const TagLayout& layout, const PinholeIntrinsics& intrinsics, const DepthMap& depth) {
  const Pose world_to_camera = pose.camera_to_world.inverse();
  std::vector<double> ratios;
  Eigen::Vector3d centre_world = Eigen::Vector3d::Zero();
  int tags = 0;
  for (const auto& detection : detections) {
    const TagLayout::Tag* tag = layout.find(detection.id);
    if (!tag) continue;
    collect_depth_ratios(*tag, world_to_camera, intrinsics, depth, ratios);
    centre_world += tag->centre();
    ++tags;
  }
  if (ratios.size() < 10 || tags == 0) return pose;
  centre_world /= tags;
  std::nth_element(ratios.begin(), ratios.begin() + static_cast<long>(ratios.size() / 2), ratios.end());
  const double scale = ratios[ratios.size() / 2];
  // Move the tags' centre along its viewing ray by `scale`, keeping the rotation.
  Pose refined = world_to_camera;
  const Eigen::Vector3d centre_camera = world_to_camera * centre_world;
  refined.translation() += (scale - 1.0) * centre_camera;
  MarkerPose result = pose;
  result.camera_to_world = refined.inverse();
  return result;
}

namespace {

/// The measured camera-frame points on a tag's face, inset by kFaceInset from its edges: the pixels
/// whose ray meets the face (as `world_to_camera` places it) within the inset square.
std::vector<Eigen::Vector3d> face_points(const TagLayout::Tag& tag, const Pose& world_to_camera,
                                         const PinholeIntrinsics& intrinsics, const DepthMap& depth) {
  const auto corner = [&](std::size_t k) { return world_to_camera * tag.corners_world[k]; };
  const Eigen::Vector3d origin = corner(0), u_axis = corner(1) - origin, v_axis = corner(3) - origin;
  const Eigen::Vector3d normal = u_axis.cross(v_axis).normalized();
  Eigen::AlignedBox2d bounds;
  for (std::size_t k = 0; k < 4; ++k) bounds.extend(intrinsics.project(corner(k)));
  std::vector<Eigen::Vector3d> points;
  const int first_row = std::max(0, static_cast<int>(bounds.min().y()));
  const int last_row = std::min(depth.height() - 1, static_cast<int>(bounds.max().y()));
  const int first_col = std::max(0, static_cast<int>(bounds.min().x()));
  const int last_col = std::min(depth.width() - 1, static_cast<int>(bounds.max().x()));
  for (int row = first_row; row <= last_row; ++row) {
    for (int col = first_col; col <= last_col; ++col) {
      if (!is_valid_depth(depth(row, col))) continue;
      const Eigen::Vector3d ray = intrinsics.ray(col, row);
      const double along = normal.dot(origin) / normal.dot(ray);
      if (!(along > 0.0)) continue;
      const Eigen::Vector3d on_face = along * ray - origin;
      const double a = on_face.dot(u_axis) / u_axis.squaredNorm(), b = on_face.dot(v_axis) / v_axis.squaredNorm();
      const auto inside = [](double x) { return x >= kFaceInset && x <= 1.0 - kFaceInset; };
      if (inside(a) && inside(b)) points.push_back(intrinsics.unproject(col, row, depth(row, col)));
    }
  }
  return points;
}

/// The least-squares plane's normal (the direction of least spread).
Eigen::Vector3d plane_normal(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d& centre) {
  centre = Eigen::Vector3d::Zero();
  for (const auto& x : points) centre += x / static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& x : points) scatter += (x - centre) * (x - centre).transpose();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
}

/// plane_normal again without the points more than three median distances off the first fit;
/// none when fewer than `min_points` remain.
std::optional<Eigen::Vector3d> robust_plane_normal(const std::vector<Eigen::Vector3d>& points, int min_points) {
  if (static_cast<int>(points.size()) < min_points) return std::nullopt;
  Eigen::Vector3d centre;
  const Eigen::Vector3d first = plane_normal(points, centre);
  std::vector<double> distances;
  distances.reserve(points.size());
  for (const auto& x : points) distances.push_back(std::abs((x - centre).dot(first)));
  std::vector<double> sorted = distances;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double limit = 3.0 * std::max(sorted[sorted.size() / 2], 1e-6);
  std::vector<Eigen::Vector3d> inliers;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (distances[i] <= limit) inliers.push_back(points[i]);
  if (static_cast<int>(inliers.size()) < min_points) return std::nullopt;
  return plane_normal(inliers, centre);
}

}  // namespace

MarkerPose refine_tilt_with_depth(const MarkerPose& pose, const std::vector<TagDetection>& detections,
                                  const TagLayout& layout, const PinholeIntrinsics& intrinsics, const DepthMap& depth,
                                  double max_view_angle_degrees, int min_points) {
  const TagLayout::Tag* tag = nullptr;
  for (const auto& detection : detections) {
    const TagLayout::Tag* known = layout.find(detection.id);
    if (!known) continue;
    if (tag) return pose;  // several tags pin the tilt themselves
    tag = known;
  }
  if (!tag) return pose;
  const Pose world_to_camera = pose.camera_to_world.inverse();
  const Eigen::Vector3d normal = world_to_camera.linear() * tag->normal();
  const Eigen::Vector3d tag_centre = world_to_camera * tag->centre();
  // Seen obliquely, the corners pin the tilt themselves.
  if (std::abs(normal.dot(tag_centre.normalized())) < std::cos(max_view_angle_degrees * EIGEN_PI / 180.0)) return pose;
  const auto measured = robust_plane_normal(face_points(*tag, world_to_camera, intrinsics, depth), min_points);
  if (!measured) return pose;
  const Eigen::Vector3d facing = measured->dot(normal) < 0.0 ? Eigen::Vector3d(-*measured) : *measured;
  if (facing.dot(normal) < std::cos(30.0 * EIGEN_PI / 180.0)) return pose;  // the depth is not the tag's
  // Turn the tag about its centre so that its face normal becomes the measured one.
  const Eigen::Matrix3d turn = Eigen::Quaterniond::FromTwoVectors(normal, facing).toRotationMatrix();
  Pose refined = world_to_camera;
  refined.linear() = turn * world_to_camera.linear();
  refined.translation() = tag_centre + turn * (world_to_camera.translation() - tag_centre);
  MarkerPose result = pose;
  result.camera_to_world = refined.inverse();
  return result;
}

std::optional<MarkerPose> estimate_camera_pose(const std::vector<TagDetection>& detections, const TagLayout& layout,
                                               const PinholeIntrinsics& intrinsics, const DepthMap& depth,
                                               double head_on_degrees) {
  const auto estimate = estimate_camera_pose(detections, layout, intrinsics);
  if (!estimate) return std::nullopt;
  // Tilt first (the face's plane), then the distance along the ray.
  const MarkerPose tilted = refine_tilt_with_depth(*estimate, detections, layout, intrinsics, depth, head_on_degrees);
  return refine_with_depth(tilted, detections, layout, intrinsics, depth);
}

void MarkerPoseStage::declare(StageBuilder& builder) {
  detections_ = builder.read(kTagDetections);
  depth_ = builder.read(kDepth);
  frame_ = builder.read(frame_buffer_);
  pose_ = builder.write(kMarkerPose);
}

void MarkerPoseStage::run(StageContext& context) {
  const std::vector<TagDetection>& detections = context.get(detections_).tags;
  const PinholeIntrinsics& intrinsics = context.get(frame_).intrinsics;
  const auto estimate = estimate_camera_pose(detections, layout_, intrinsics, context.get(depth_));
  CameraPose& out = context.get(pose_);
  if (estimate) last_ = estimate;
  out.valid = last_.has_value();
  out.held = last_.has_value() && !estimate;
  out.camera_to_world = last_ ? last_->camera_to_world : Pose::Identity();
  out.tags_used = estimate ? estimate->tags_used : 0;
  out.reprojection_rms_px = estimate ? estimate->reprojection_rms_px : 0.0;
  out.source = PoseSource::Marker;
  out.failure = estimate ? "" : "no known tag in view";
}

}  // namespace relight::capture
