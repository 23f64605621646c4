#pragma once
// Camera models. Camera frame convention (OpenCV/TUM): x right, y down, z forward (optical axis).
#include <Eigen/Core>
#include <array>
#include <optional>
#include <string_view>

#include "relight/core/named_values.h"

namespace relight {

/// Pinhole intrinsics in pixels; pixel centres at integer coordinates (u = col, v = row).
struct PinholeIntrinsics {
  double fx = 525.0;
  double fy = 525.0;
  double cx = 319.5;
  double cy = 239.5;
  int width = 640;
  int height = 480;

  /// Kinect v1 / ROS defaults (fx = fy = 525, cx = 319.5, cy = 239.5, 640x480).
  static PinholeIntrinsics kinect_v1() { return {}; }
  /// TUM RGB-D calibrated colour cameras: "fr1", "fr2", "fr3", or "kinect" for the defaults
  /// (kIntrinsicsPresets).
  static std::optional<PinholeIntrinsics> preset(std::string_view name);

  /// Pixel (u, v) of a camera-frame point; z must be > 0.
  [[nodiscard]] Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  /// Camera-frame point at pixel (u, v) with depth z (metres along the optical axis).
  [[nodiscard]] Eigen::Vector3d unproject(double u, double v, double z) const {
    return {(u - cx) / fx * z, (v - cy) / fy * z, z};
  }
  /// Unit-less ray direction through pixel (u, v) with z = 1.
  [[nodiscard]] Eigen::Vector3d ray(double u, double v) const { return unproject(u, v, 1.0); }

  friend bool operator==(const PinholeIntrinsics&, const PinholeIntrinsics&) = default;
};

/// The intrinsics presets by name (--intrinsics): the Kinect v1 / ROS defaults and the TUM RGB-D
/// calibrated colour cameras (cvg.cit.tum.de, "file formats" page).
inline constexpr std::array<NamedValue<PinholeIntrinsics>, 4> kIntrinsicsPresets{
    {{"kinect", PinholeIntrinsics{}},
     {"fr1", PinholeIntrinsics{517.3, 516.5, 318.6, 255.3, 640, 480}},
     {"fr2", PinholeIntrinsics{520.9, 521.0, 325.1, 249.7, 640, 480}},
     {"fr3", PinholeIntrinsics{535.4, 539.2, 320.1, 247.6, 640, 480}}}};

/// Equidistant fisheye (r = f * theta) as used for the light probe: centre (cx, cy) and the
/// pixel radius at which theta reaches max_theta (pi/2 for a 180 degree lens). Directions are
/// in the probe's own frame (z along the optical axis, x right, y down in the image).
struct FisheyeCamera {
  double cx = 255.5;
  double cy = 255.5;
  double radius = 256.0;                 ///< pixels at theta = max_theta
  double max_theta = 1.5707963267948966;  ///< half field of view in radians
  int width = 512;
  int height = 512;

  [[nodiscard]] double focal() const { return radius / max_theta; }
  /// Unit direction for pixel (u, v); nullopt outside the image circle.
  [[nodiscard]] std::optional<Eigen::Vector3d> unproject(double u, double v) const;
  /// Pixel of a unit direction; nullopt when outside the field of view.
  [[nodiscard]] std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& direction) const;
  /// Solid angle (steradians) covered by the unit pixel square centred at (u, v); 0 outside.
  /// Equidistant mapping: d(omega) = sin(theta) / (f^2 * theta) du dv.
  [[nodiscard]] double pixel_solid_angle(double u, double v) const;
};

}  // namespace relight
