#pragma once
// The reflection model that BRDF estimation fits and the re-render uses (Knecht's dissertation
// §4.4, eqs. 4.12-4.15), in the radiometric form of the synthetic scene (synth/scene.h):
//
//   L(x) = k_d * ( A + sum_l E_l(x) / pi )                                      (diffuse)
//        + sum_l E_l(x) * k_s * (n + 2) / (2 pi) * <omega_o . r_l>+^n           (specular)
//
// with E_l(x) the RGB irradiance light l delivers to the surface point x (cosine included),
// A an optional constant ambient radiance (an unoccluded environment that the light set does not
// contain; zero when the lights were sampled from the whole probe), r_l the mirror direction of
// the light direction omega_l about the normal and omega_o the unit direction towards the camera.
//
// Knecht writes the terms as I_l k_d <n.omega_l>+ and I_l k_s <omega_o.r_l>+^n; with
// I_l <n.omega_l>+ = E_l / pi the diffuse terms agree, and his k_s equals ours times (n + 2) / 2.
// We keep the normalised (energy-conserving) lobe so that k_s means the same as in the synthetic
// scene's materials and stays nearly independent of n in the fit.
//
// Everything here works in the camera frame (x right, y down, z forward): normals and positions
// come from the reconstruction, lights are moved into the camera frame once per frame.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/core/srgb.h"
#include "relight/lights/light_set.h"

namespace relight::brdf {

/// One light in the camera frame.
struct ShadingLight {
  bool point = false;                                 ///< a point or spot light (at `vector`), else directional
  Eigen::Vector3f vector = Eigen::Vector3f::UnitZ();  ///< unit direction towards the light, or the point light's position
  Eigen::Vector3f power = Eigen::Vector3f::Zero();    ///< LightSet units: irradiance (directional), W/sr (point)
  lights::Light spot{};  ///< a spot's cone in the camera frame (kind Spot), for lights::spot_falloff
};

/// The lights used for estimation, in the camera frame.
struct ShadingLights {
  std::vector<ShadingLight> lights;
  Eigen::Vector3f ambient = Eigen::Vector3f::Zero();  ///< A above: constant radiance, linear RGB
};

/// Moves a world-frame LightSet into the camera frame of `camera_to_world`; only lights with
/// `real` set take part (virtual objects' lights do not light the real surfaces' colours).
[[nodiscard]] ShadingLights to_camera_frame(const lights::LightSet& set, const Pose& camera_to_world,
                                            const Eigen::Vector3f& ambient = Eigen::Vector3f::Zero());

/// The most directional lights BRDF estimation shades with. A set with more (a probe's 64 for
/// replay's --environment vpls) is merged down to them first (lights/merge_lights.h): the
/// specular fit's cost grows with every light (measured at 640x480: 355 ms a frame with 64
/// lights, 45 ms with 8) and the merged clusters shade alike to within 1 / cos(theta / 2).
inline constexpr std::size_t kEstimationDirectionalLights = 8;

/// to_camera_frame() of `set` with at most kEstimationDirectionalLights directional lights.
[[nodiscard]] ShadingLights estimation_lights(const lights::LightSet& set, const Pose& camera_to_world,
                                              const Eigen::Vector3f& ambient = Eigen::Vector3f::Zero());

/// Unit direction towards light `light` from camera-frame point `position` and the irradiance
/// factor it delivers there without the cosine: power for directional lights, power / d^2 for
/// point lights.
struct LightAtPoint {
  Eigen::Vector3f direction;
  Eigen::Vector3f irradiance;  ///< at normal incidence
};
[[nodiscard]] LightAtPoint light_at(const ShadingLight& light, const Eigen::Vector3f& position);

/// Diffuse shading factor D = A + sum_l E_l / pi at a point, i.e. L_diffuse = k_d * D.
[[nodiscard]] Eigen::Vector3f diffuse_shading(const ShadingLights& lights, const Eigen::Vector3f& position,
                                              const Eigen::Vector3f& normal);

/// The full model above for one point (camera frame; the camera sits at the origin).
[[nodiscard]] Eigen::Vector3f phong_radiance(const ShadingLights& lights, const Eigen::Vector3f& position,
                                             const Eigen::Vector3f& normal, const Eigen::Vector3f& kd, float ks,
                                             float n);

/// sRGB (IEC 61966-2-1) 8-bit value -> linear, and its 256-entry table (core/srgb.h).
using relight::srgb8_linear_table;
using relight::srgb8_to_linear;
/// The camera image as linear RGB (the inverse of synth::encode_color with exposure 1).
[[nodiscard]] RadianceImage linearize(const ColorImage& color);

}  // namespace relight::brdf
