#pragma once
// The real light from the RGB-D frames themselves, for sequences without a light probe (every
// TUM recording, most users' own .oni). Inverse shading with the model of shading.h for diffuse
// surfaces, I(x) = k_d(x) E(n(x)) / pi, where
//
//   E(n, x) = E_sh(n) - P max(0, n . d) (1 - V(x, d))
//
// E_sh is the order-2 spherical-harmonics irradiance of the unoccluded environment (lights/
// spherical_harmonics.h, world frame), (d, P) the dominant distant light and V(x, d) whether x
// sees it. Diffuse shading alone determines only E_sh (Ramamoorthi & Hanrahan); the dominant
// light's direction and power come from cast shadows, where a surface of one material is darker
// than its normal explains.
//
// Per frame (add_frame):
//  1. Accumulation in the world frame (the camera moves, the light does not): every stride-th
//     pixel with a position, a normal facing the camera, no highlight and no clipped channel adds
//     its linear colour and world normal to a voxel of voxel_size (a running mean; a static camera
//     does not pile up copies of one view).
//  2. Alternation (Knecht's k_d estimate assumes the lights, the light fit assumes k_d): from a
//     constant E, k_d = pi I / E(n) per voxel, K-means (KMeansCpu) on chromaticity into materials
//     (close centres merge, so one material is not split by its shading), a robust (Cauchy-weighted, so shadows and
//     interreflections count little) least- squares fit of E_sh's 27 coefficients given the materials' albedos, and the
//     albedos given E_sh, `iterations` times.
//  3. Scale. I = k_d E / pi only fixes the product: the brightest white_share of the samples'
//     k_d is taken to have albedo luminance white_albedo (Land's white patch, with a percentile
//     for the maximum; a white wall or paper is ~0.7-0.85). Shadows and shading of the real surfaces
//     do not depend on this choice (DIR's Delta L scales with k_d E); only how bright a virtual
//     object of given albedo looks does.
//  4. Shadows (this frame, camera frame): for candidate directions (a Fibonacci sphere, then finer
//     grids around the best), V(x, d) by marching the ray through the position map (screen-space
//     shadows; only directions on the bright side of E_sh, E_sh(d) > E_sh(-d)); each occluded sample is compared with
//     the lit samples of its neighbourhood (8 cm world cell, same material and normal: they share the lamp's falloff
//     and sheen, which the SH cannot follow); the direction whose shadow term explains the largest share of the
//     neighbourhoods' squared error, with P >= 0 by least squares. Frames whose best share is below
//     min_shadow_share add nothing; the others add their direction and P / E_sh(d) to running,
//     share-weighted means in the world frame.
//  5. The estimate: the dominant light (from the shadows, else the best-lit normal the camera saw
//     with the power of E_sh's band 1 along it, "shading" evidence), P capped at E_sh(d) (a surface facing the
//     light receives at least the light), and the ambient rest E_sh minus the light's projection.
//     environment_map() paints both into a lat-long radiance map (world frame, probe_geometry.h's
//     convention: the light a disc of light_radius_degrees) that the probe's light extraction
//     turns into lights like any probe.
//
// Every sum is weighted by locality (see locality_radius): the environment is the one of the
// neighbourhood the camera looks at, where virtual objects go.
//
// Departures from the plan: one dominant light, not several; highlights on glossy
// materials are masked out rather than used as direction evidence.
//
// State: on the synthetic room (tests/brdf, one view) the table's irradiance is within 15 %, the
// dominant light's direction 14 degrees off (the goal is 10: the lamp's shadows cover 1.4 % of
// the table and the screen-space march finds a fifth of them), and the white patch takes a
// bright yellow for white (the light's chromaticity 0.13 off).
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <unordered_map>
#include <vector>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/lights/spherical_harmonics.h"

namespace relight::brdf {

class KMeansEngine;

struct LightEstimationOptions {
  int stride = 4;                      ///< pixels: every stride-th pixel of every stride-th row
  double voxel_size = 0.03;            ///< metres, the world-frame accumulation cells
  std::size_t max_voxels = 40000;      ///< new surfaces beyond this are not added
  std::size_t max_fit_samples = 6000;  ///< voxels one fit uses (an even stride over them)
  int clusters = 6;                    ///< K-means' K; centres closer than merge_distance merge
  double merge_distance = 0.08;        ///< feature units: 0.04 of chromaticity
  int iterations = 5;                  ///< albedo / light alternations per frame
  double white_albedo = 0.75;          ///< luminance albedo of the brightest samples (step 3)
  double white_share = 0.03;           ///< the brightest share of samples that is "white" (step 3)
  int shadow_stride = 2;               ///< pixels, as stride, for the cast shadows (they are small)
  int shadow_samples = 6000;           ///< this frame's pixels tested for cast shadows, at most
  double min_shadow_share = 0.005;     ///< of the neighbourhoods' squared error (step 4)
  int min_shadowed_samples = 8;        ///< compared with lit neighbours (step 4)
  double light_radius_degrees = 3.0;   ///< the dominant light's disc in environment_map()
  int map_width = 128;                 ///< environment_map(): width x width / 2
  /// Metres: samples count with weight exp(-d^2 / 2 r^2) by their distance d to the focus (the
  /// median point of the image centre, averaged over frames). Room lights are near: the floor
  /// under a table receives a fraction of the table's light from the same directions, which one
  /// distant environment cannot explain; the estimate holds for where the camera looks.
  double locality_radius = 0.4;
  std::uint64_t seed = 1;
  int threads = 0;  ///< the shadow search's workers (core/parallel.h; 0 = all)
};

enum class LightEvidence { None, Shading, Shadows };
[[nodiscard]] const char* to_string(LightEvidence evidence);

struct LightEstimate {
  lights::ShRgb irradiance;  ///< E_sh: irradiance coefficients, world frame, after the scale
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< the dominant light, towards it
  Eigen::Vector3d power = Eigen::Vector3d::Zero();       ///< its irradiance at normal incidence
  LightEvidence evidence = LightEvidence::None;
  double shadow_share = 0.0;  ///< this frame's share of the residual explained by the shadow term
  int shadow_frames = 0;      ///< frames whose shadows took part
  std::size_t voxels = 0;
  std::size_t fit_samples = 0;
  std::vector<Eigen::Vector3d> albedos;  ///< per material, after the scale
  std::vector<double> shares;            ///< per material, of the fit's samples
  double fit_rms = 0.0;                  ///< relative, of the luminance residual (Cauchy-weighted)

  /// The ambient rest: E_sh minus the dominant light's SH projection, as radiance coefficients.
  [[nodiscard]] lights::ShRgb ambient_radiance() const;
  /// Irradiance on an unoccluded surface of world normal `normal` (E_sh(n)).
  [[nodiscard]] Eigen::Vector3d irradiance_at(const Eigen::Vector3d& normal) const {
    return irradiance.evaluate(normal.normalized());
  }
  [[nodiscard]] nlohmann::ordered_json to_json() const;
};

class LightEstimator {
 public:
  explicit LightEstimator(LightEstimationOptions options = {});
  ~LightEstimator();
  LightEstimator(LightEstimator&&) noexcept;
  LightEstimator& operator=(LightEstimator&&) noexcept;

  /// One frame: `color` the 8-bit sRGB camera image (highlights removed), `highlights` (may be
  /// null) pixels to skip, camera-frame positions and normals, the camera's intrinsics and pose.
  void add_frame(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                 const NormalMap& normals, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world);

  [[nodiscard]] const LightEstimate& estimate() const { return estimate_; }
  /// The estimate as a width x width/2 lat-long radiance map in the world frame (step 5).
  [[nodiscard]] RadianceImage environment_map() const;

 private:
  struct Voxel {
    Eigen::Vector3d colour_sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d position_sum = Eigen::Vector3d::Zero();
    double count = 0.0;
  };
  struct Sample {
    Eigen::Vector3d normal;  ///< world frame, unit
    Eigen::Vector3d colour;  ///< linear RGB
    double locality;         ///< weight by the distance to the focus
  };
  void accumulate(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                  const NormalMap& normals, const Pose& camera_to_world);
  void fit();
  void fit_shadows(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                   const NormalMap& normals, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world);
  /// exp(-d^2 / (2 locality_radius^2)), d the distance of world point `world` to the focus.
  [[nodiscard]] double locality(const Eigen::Vector3d& world) const;
  [[nodiscard]] int material_of(const Eigen::Vector3d& colour, const Eigen::Vector3d& world_normal) const;

  LightEstimationOptions options_;
  std::unordered_map<std::uint64_t, std::uint32_t> voxel_index_;
  std::vector<Voxel> voxels_;
  std::unique_ptr<KMeansEngine> engine_;
  std::vector<Eigen::Vector3f> centres_;                         ///< materials in feature space (light_estimation.cpp)
  Eigen::Vector3d brightest_normal_ = Eigen::Vector3d::UnitZ();  ///< of the fit's samples, by E_sh
  Eigen::Vector3d shadow_direction_sum_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d shadow_fraction_sum_ = Eigen::Vector3d::Zero();  ///< P / E_sh(d), share-weighted
  double shadow_weight_ = 0.0;
  Eigen::Vector3d focus_sum_ = Eigen::Vector3d::Zero();  ///< the frames' focus points
  double focus_frames_ = 0.0;
  Eigen::Vector3d light_colour_ = Eigen::Vector3d::Ones();  ///< luminance 1, from the white patch
  LightEstimate estimate_;
};

}  // namespace relight::brdf
