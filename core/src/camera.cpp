#include "relight/core/camera.h"

#include <algorithm>
#include <cmath>

namespace relight {

std::optional<PinholeIntrinsics> PinholeIntrinsics::preset(std::string_view name) {
  // TUM RGB-D colour camera calibrations (cvg.cit.tum.de, "file formats" page).
  if (name == "kinect" || name == "default") return kinect_v1();
  if (name == "fr1" || name == "freiburg1") return PinholeIntrinsics{517.3, 516.5, 318.6, 255.3, 640, 480};
  if (name == "fr2" || name == "freiburg2") return PinholeIntrinsics{520.9, 521.0, 325.1, 249.7, 640, 480};
  if (name == "fr3" || name == "freiburg3") return PinholeIntrinsics{535.4, 539.2, 320.1, 247.6, 640, 480};
  return std::nullopt;
}

std::optional<Eigen::Vector3d> FisheyeCamera::unproject(double u, double v) const {
  const double du = u - cx;
  const double dv = v - cy;
  const double r = std::hypot(du, dv);
  const double theta = r / focal();
  if (theta > max_theta) return std::nullopt;
  if (r < 1e-12) return Eigen::Vector3d::UnitZ();
  const double s = std::sin(theta) / r;
  return Eigen::Vector3d(du * s, dv * s, std::cos(theta));
}

std::optional<Eigen::Vector2d> FisheyeCamera::project(const Eigen::Vector3d& direction) const {
  const Eigen::Vector3d d = direction.normalized();
  const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
  if (theta > max_theta) return std::nullopt;
  const double planar = std::hypot(d.x(), d.y());
  if (planar < 1e-12) return Eigen::Vector2d(cx, cy);
  const double r = focal() * theta;
  return Eigen::Vector2d(cx + r * d.x() / planar, cy + r * d.y() / planar);
}

double FisheyeCamera::pixel_solid_angle(double u, double v) const {
  const double r = std::hypot(u - cx, v - cy);
  const double f = focal();
  const double theta = r / f;
  if (theta > max_theta) return 0.0;
  // sin(theta)/theta -> 1 at the centre.
  const double sinc = theta < 1e-9 ? 1.0 : std::sin(theta) / theta;
  return sinc / (f * f);
}

}  // namespace relight
