#pragma once
// Where each probe pixel looks and how much of the sphere it covers.
//
// Two probe projections:
//  - Fisheye: an equidistant fisheye (r = f * theta, FisheyeCamera), e.g. the 180-degree probe
//    camera of Knecht's setup (dissertation section 4.2) or synth::render_probe. Pixels outside
//    the image circle are masked (solid angle 0).
//  - Equirectangular (lat-long) environment maps, e.g. Debevec's probes: row 0 looks along the
//    probe's +z, column u at azimuth phi = 2 pi (u + 0.5) / width around it:
//    d = (sin theta cos phi, sin theta sin phi, cos theta), theta = pi (v + 0.5) / height.
// probe_to_world rotates probe-frame directions into the scene frame (columns: probe x, y, z).
//
// Solid angle per pixel: equidistant fisheye d(omega) = sin(theta) / (f^2 theta) du dv
// (FisheyeCamera::pixel_solid_angle); lat-long d(omega) = sin(theta) dtheta dphi.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "relight/core/camera.h"
#include "relight/core/image.h"

namespace relight::lights {

/// FromAspect: equirectangular when the image is twice as wide as tall, else fisheye (resolved
/// by ProbeGeometry, whose calibration() is then one of the other two).
enum class ProbeProjection { Fisheye, Equirectangular, FromAspect };

struct ProbeCalibration {
  ProbeProjection projection = ProbeProjection::Fisheye;
  /// Fisheye only: centre, radius and field of view (width/height come from the image).
  FisheyeCamera fisheye{};
  /// Fisheye only: the image circle touches the image's borders, whatever its size (centre and
  /// radius of `fisheye` are then taken from the image, as centred_fisheye does).
  bool centred_on_image = false;
  Eigen::Matrix3d probe_to_world = Eigen::Matrix3d::Identity();

  /// A 180-degree fisheye whose image circle touches the borders of a width x height image.
  static ProbeCalibration centred_fisheye(int width, int height);
  static ProbeCalibration equirectangular();
};

/// Per-pixel world direction and solid angle for one calibration and image size. Computed once
/// (the calibration is fixed over a sequence) and shared by every sampler and by the GPU.
class ProbeGeometry {
 public:
  ProbeGeometry() = default;
  ProbeGeometry(const ProbeCalibration& calibration, int width, int height);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] const ProbeCalibration& calibration() const { return calibration_; }
  /// Solid angle (sr) of pixel (row, col); 0 outside the image circle.
  [[nodiscard]] float solid_angle(int row, int col) const { return solid_angle_[index(row, col)]; }
  [[nodiscard]] const std::vector<float>& solid_angles() const { return solid_angle_; }
  /// Sum of all pixel solid angles (2 pi for a 180-degree fisheye, 4 pi for lat-long).
  [[nodiscard]] double total_solid_angle() const { return total_solid_angle_; }

  /// World direction at continuous pixel coordinates (u = col, v = row; pixel centres at
  /// integers); nullopt outside the image circle.
  [[nodiscard]] std::optional<Eigen::Vector3d> direction(double u, double v) const;
  /// Pixel coordinates (u, v) of a world direction; nullopt when the probe does not see it.
  [[nodiscard]] std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& world_direction) const;

 private:
  [[nodiscard]] std::size_t index(int row, int col) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(col);
  }
  ProbeCalibration calibration_;
  int width_ = 0;
  int height_ = 0;
  std::vector<float> solid_angle_;
  double total_solid_angle_ = 0.0;
};

/// Resamples a lat-long map into an equidistant fisheye image of `fisheye` looking along
/// world_up (nearest-neighbour lookups, `samples` x `samples` per pixel averaged).
[[nodiscard]] RadianceImage equirectangular_to_fisheye(const RadianceImage& latlong,
                                                       const Eigen::Matrix3d& latlong_to_world,
                                                       const FisheyeCamera& fisheye,
                                                       const Eigen::Matrix3d& fisheye_to_world, int samples = 2);

}  // namespace relight::lights
