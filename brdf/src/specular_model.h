#pragma once
// The per-sample model of the specular fit, templated on the scalar so that Nelder-Mead (double)
// and Ceres (Jets) evaluate exactly the same expression, with the Phong terms of core/phong.h. Private to relight_brdf.
#include <cmath>
#include <numbers>
#include <vector>

#include "relight/brdf/specular_fit.h"
#include "relight/core/phong.h"

namespace relight::brdf::detail {

/// Lights reordered so that the moving ones come first.
inline ShadingLights moving_first(const ShadingLights& lights, const std::vector<int>& moving) {
  ShadingLights out;
  out.ambient = lights.ambient;
  for (const int i : moving) out.lights.push_back(lights.lights[static_cast<std::size_t>(i)]);
  for (std::size_t i = 0; i < lights.lights.size(); ++i) {
    bool is_moving = false;
    for (const int m : moving) is_moving = is_moving || static_cast<std::size_t>(m) == i;
    if (!is_moving) out.lights.push_back(lights.lights[i]);
  }
  return out;
}

/// Model radiance of one sample. `offsets[l]` (3 values) moves light l for l < moving.
template <class T>
void model_radiance(const SpecularSample& s, const Eigen::Vector3f& kd, const ShadingLights& lights, const T& ks,
                    const T& n, const T* const* offsets, int moving, T out[3]) {
  using std::pow;
  using std::sqrt;
  const T inv_pi = T(std::numbers::inv_pi);
  for (int c = 0; c < 3; ++c) out[c] = T(double(kd[c]) * double(lights.ambient[c]));
  const T px = T(double(s.position.x())), py = T(double(s.position.y())), pz = T(double(s.position.z()));
  const T nx = T(double(s.normal.x())), ny = T(double(s.normal.y())), nz = T(double(s.normal.z()));
  const T view_scale = T(1.0) / sqrt(px * px + py * py + pz * pz);
  const T vx = -px * view_scale, vy = -py * view_scale, vz = -pz * view_scale;
  const T lobe_scale = ks * phong_lobe_normalisation(n);
  for (std::size_t l = 0; l < lights.lights.size(); ++l) {
    const ShadingLight& light = lights.lights[l];
    T lx = T(double(light.vector.x())), ly = T(double(light.vector.y())), lz = T(double(light.vector.z()));
    if (static_cast<int>(l) < moving) {
      lx += offsets[l][0];
      ly += offsets[l][1];
      lz += offsets[l][2];
    }
    T scale;  // irradiance factor per unit power at normal incidence
    if (light.point) {
      lx -= px;
      ly -= py;
      lz -= pz;
      const T d2 = lx * lx + ly * ly + lz * lz;
      const T inv_d = T(1.0) / sqrt(d2);
      lx *= inv_d;
      ly *= inv_d;
      lz *= inv_d;
      scale = T(1.0) / d2;
    } else {
      const T inv_len = T(1.0) / sqrt(lx * lx + ly * ly + lz * lz);
      lx *= inv_len;
      ly *= inv_len;
      lz *= inv_len;
      scale = T(1.0);
    }
    const T cosine = nx * lx + ny * ly + nz * lz;
    if (!(cosine > T(0.0))) continue;
    const T rv = (T(2.0) * cosine * nx - lx) * vx + (T(2.0) * cosine * ny - ly) * vy + (T(2.0) * cosine * nz - lz) * vz;
    const T lobe = phong_lobe(n, rv);
    const T e = scale * cosine;
    for (int c = 0; c < 3; ++c) {
      out[c] += e * T(double(light.power[c])) * (T(double(kd[c])) * inv_pi + lobe_scale * lobe);
    }
  }
}

}  // namespace relight::brdf::detail
