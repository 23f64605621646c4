#pragma once
// Probes with known answers for the light tests: analytic fisheye/lat-long images, and the
// synthetic scene's probe (rendered once per test process) with its lights' true directions
// and irradiances.
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "relight/lights/light_set.h"
#include "relight/lights/probe_geometry.h"
#include "relight/synth/probe.h"

namespace relight::test {

inline double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }
inline double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }
inline double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}
inline Eigen::Vector3d spherical(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

/// Every pixel of `geometry` (supersampled s x s) set to radiance(direction).
template <class Radiance>
RadianceImage analytic_probe(const lights::ProbeGeometry& geometry, Radiance radiance, int s = 3) {
  RadianceImage image(geometry.width(), geometry.height());
  for (int row = 0; row < image.height(); ++row) {
    for (int col = 0; col < image.width(); ++col) {
      if (geometry.solid_angle(row, col) == 0.f) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          const auto d = geometry.direction(col - 0.5 + (j + 0.5) / s, row - 0.5 + (i + 0.5) / s);
          if (d) sum += radiance(*d);
        }
      }
      sum /= s * s;
      image(row, col) = {static_cast<float>(sum.x()), static_cast<float>(sum.y()), static_cast<float>(sum.z())};
    }
  }
  return image;
}

/// A dim uniform sky of radiance 0.05 with one disc emitter of `radius` around `direction`
/// whose radiance is `peak` (so it carries almost all the energy).
inline RadianceImage emitter_probe(const lights::ProbeGeometry& geometry, const Eigen::Vector3d& direction,
                                   double radius, double peak = 20000.0) {
  return analytic_probe(geometry, [&](const Eigen::Vector3d& d) -> Eigen::Vector3d {
    return angle_between(d, direction) < radius ? Eigen::Vector3d::Constant(peak) : Eigen::Vector3d::Constant(0.05);
  });
}

/// Irradiance on a surface of normal n by direct integration over the probe's pixels.
inline Eigen::Vector3d probe_irradiance(const RadianceImage& probe, const lights::ProbeGeometry& geometry,
                                        const Eigen::Vector3d& normal) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int row = 0; row < probe.height(); ++row) {
    for (int col = 0; col < probe.width(); ++col) {
      const double omega = geometry.solid_angle(row, col);
      if (omega == 0.0) continue;
      const Float3& l = probe(row, col);
      sum += omega * std::max(0.0, normal.dot(*geometry.direction(col, row))) * Eigen::Vector3d(l.x, l.y, l.z);
    }
  }
  return sum;
}

struct SynthProbe {
  synth::Scene scene;
  synth::LightProbe probe;
  RadianceImage image;
  lights::ProbeGeometry geometry;
};

/// The synthetic scene's probe at 256 x 256 (0.7 degrees per pixel; the emitters are ~3 pixels
/// across), with `scene` modified by `edit` first.
template <class Edit>
SynthProbe render_synth_probe(Edit edit) {
  SynthProbe s;
  s.scene = synth::default_indoor_scene();
  edit(s.scene);
  s.probe = synth::default_probe(s.scene);
  s.probe.camera.width = s.probe.camera.height = 256;
  s.probe.camera.cx = s.probe.camera.cy = 127.5;
  s.probe.camera.radius = 128.0;
  s.image = synth::render_probe(s.scene, s.probe);
  lights::ProbeCalibration calibration;
  calibration.fisheye = s.probe.camera;
  calibration.probe_to_world = s.probe.probe_to_world;
  s.geometry = lights::ProbeGeometry(calibration, 256, 256);
  return s;
}

inline const SynthProbe& default_synth_probe() {
  static const SynthProbe probe = render_synth_probe([](synth::Scene&) {});
  return probe;
}

/// True direction from the probe to a scene light, and the irradiance it delivers there.
inline Eigen::Vector3d light_direction(const SynthProbe& s, const synth::PointLight& light) {
  return (light.position - s.probe.position).normalized();
}
inline Eigen::Vector3d light_irradiance(const SynthProbe& s, const synth::PointLight& light) {
  return light.colour * light.intensity / (light.position - s.probe.position).squaredNorm();
}

}  // namespace relight::test
