#include "relight/core/camera.h"

#include <algorithm>
#include <cmath>

namespace relight {

std::optional<PinholeIntrinsics> PinholeIntrinsics::preset(std::string_view name) {
  for (const auto& entry : kIntrinsicsPresets)
    if (entry.name == name) return entry.value;
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
