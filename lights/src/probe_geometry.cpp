#include "relight/lights/probe_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/core/error.h"

namespace relight::lights {

namespace {

constexpr double kPi = std::numbers::pi;

std::optional<Eigen::Vector3d> equirect_direction(double u, double v, int width, int height) {
  const double theta = kPi * (v + 0.5) / height;
  const double phi = 2.0 * kPi * (u + 0.5) / width;
  if (theta < 0.0 || theta > kPi) return std::nullopt;
  return Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}

Eigen::Vector2d equirect_pixel(const Eigen::Vector3d& d, int width, int height) {
  const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
  double phi = std::atan2(d.y(), d.x());
  if (phi < 0.0) phi += 2.0 * kPi;
  return {phi / (2.0 * kPi) * width - 0.5, theta / kPi * height - 0.5};
}

}  // namespace

ProbeCalibration ProbeCalibration::centred_fisheye(int width, int height) {
  ProbeCalibration calibration;
  calibration.fisheye.width = width;
  calibration.fisheye.height = height;
  calibration.fisheye.cx = (width - 1) / 2.0;
  calibration.fisheye.cy = (height - 1) / 2.0;
  calibration.fisheye.radius = std::min(width, height) / 2.0;
  return calibration;
}

ProbeCalibration ProbeCalibration::equirectangular() {
  ProbeCalibration calibration;
  calibration.projection = ProbeProjection::Equirectangular;
  return calibration;
}

ProbeGeometry::ProbeGeometry(const ProbeCalibration& calibration, int width, int height)
    : calibration_(calibration), width_(width), height_(height) {
  if (width <= 0 || height <= 0) throw Error("light probe: empty image");
  if (calibration_.projection == ProbeProjection::FromAspect) {
    calibration_.projection = width == 2 * height ? ProbeProjection::Equirectangular : ProbeProjection::Fisheye;
  }
  if (calibration.centred_on_image) {
    const ProbeCalibration centred = ProbeCalibration::centred_fisheye(width, height);
    calibration_.fisheye.cx = centred.fisheye.cx;
    calibration_.fisheye.cy = centred.fisheye.cy;
    calibration_.fisheye.radius = centred.fisheye.radius;
  }
  calibration_.fisheye.width = width;
  calibration_.fisheye.height = height;
  if (calibration_.projection == ProbeProjection::Fisheye &&
      (!(calibration_.fisheye.radius > 0.0) || !(calibration_.fisheye.max_theta > 0.0) ||
       calibration_.fisheye.max_theta > kPi)) {
    throw Error("light probe: fisheye radius and field of view must be positive (fov at most 360 degrees)");
  }
  solid_angle_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      double omega = 0.0;
      if (calibration_.projection == ProbeProjection::Fisheye) {
        omega = calibration_.fisheye.pixel_solid_angle(col, row);
      } else {
        const double theta = kPi * (row + 0.5) / height;
        omega = (2.0 * kPi / width) * (kPi / height) * std::sin(theta);
      }
      solid_angle_[index(row, col)] = static_cast<float>(omega);
      total_solid_angle_ += omega;
    }
  }
}

std::optional<Eigen::Vector3d> ProbeGeometry::direction(double u, double v) const {
  const auto local = calibration_.projection == ProbeProjection::Fisheye
                         ? calibration_.fisheye.unproject(u, v)
                         : equirect_direction(u, v, width_, height_);
  if (!local) return std::nullopt;
  return (calibration_.probe_to_world * *local).normalized();
}

std::optional<Eigen::Vector2d> ProbeGeometry::project(const Eigen::Vector3d& world_direction) const {
  const Eigen::Vector3d local = calibration_.probe_to_world.transpose() * world_direction.normalized();
  if (calibration_.projection == ProbeProjection::Fisheye) return calibration_.fisheye.project(local);
  return equirect_pixel(local, width_, height_);
}

RadianceImage equirectangular_to_fisheye(const RadianceImage& latlong, const Eigen::Matrix3d& latlong_to_world,
                                         const FisheyeCamera& fisheye, const Eigen::Matrix3d& fisheye_to_world,
                                         int samples) {
  if (latlong.empty()) throw Error("equirectangular_to_fisheye: empty lat-long map");
  ProbeCalibration source = ProbeCalibration::equirectangular();
  source.probe_to_world = latlong_to_world;
  const ProbeGeometry source_geometry(source, latlong.width(), latlong.height());
  RadianceImage out(fisheye.width, fisheye.height);
  const int s = std::max(1, samples);
  for (int row = 0; row < fisheye.height; ++row) {
    for (int col = 0; col < fisheye.width; ++col) {
      Float3 sum{};
      int inside = 0;
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          const auto local = fisheye.unproject(col - 0.5 + (j + 0.5) / s, row - 0.5 + (i + 0.5) / s);
          if (!local) continue;
          const Eigen::Vector2d uv = *source_geometry.project(fisheye_to_world * *local);
          const int u = std::clamp(static_cast<int>(std::lround(uv.x())), 0, latlong.width() - 1);
          const int v = std::clamp(static_cast<int>(std::lround(uv.y())), 0, latlong.height() - 1);
          sum += latlong(v, (u + latlong.width()) % latlong.width());
          ++inside;
        }
      }
      out(row, col) = inside > 0 ? (1.f / static_cast<float>(inside)) * sum : Float3{};
    }
  }
  return out;
}

}  // namespace relight::lights
