#pragma once
// Specular fit per cluster (Knecht §4.4.4, eq. 4.15). With k_d fixed to the cluster's centre,
// find the scalar k_s (white highlights) and the Phong exponent n, letting the strongest lights
// move within a small box (they come from importance sampling and need not be exact), that
// minimise over the cluster's pixel samples i
//
//   F = sum_i sum_c ( L_i,c - model_c(x_i; k_d, k_s, n, lights) )^2
//
// with the model of shading.h (both the diffuse and the specular term subtracted). Two solvers
// behind one interface, both starting from the best of a coarse grid of exponents with each
// one's least-squares k_s (for fixed lights and n the model is linear in k_s), and both
// evaluating F over structure-of-arrays samples (src/specular_terms.h):
//   - Nelder-Mead (own implementation), every vertex projected onto the parameter box, in
//     phases: (A) log n alone with the lights fixed, every vertex taking its least-squares k_s
//     (variable projection: the same minimum as over (k_s, log n), with a one-dimensional
//     simplex); (B) if the residual is still above light_refine_rms and the cluster is not
//     diffuse, every parameter on a subset of 256 samples, restarted from the best vertex with a
//     fresh simplex until a restart no longer improves F (stopped after a 150-evaluation probe
//     that lowers F by less than 10 %); (C) phase A again on all samples with the moved lights,
//     kept if F drops;
//   - Ceres, Levenberg-Marquardt with parameter bounds on every block, in the same phases:
//     (k_s, n) as one residual block over all samples with the analytic Jacobian; under the
//     same condition as phase B, blocks (k_s, n) and one 3-vector offset per moving light in one
//     ceres::AutoDiffCostFunction over a 128-sample subset (stopped after a 5-iteration probe
//     that lowers the cost by less than 10 %, or at a relative cost change of 1e-4); (k_s, n)
//     again on all samples with the moved lights.
// Ceres stays out of this header (compile time, docs/platform.md).
//
// When the fit's RMS residual stays above `max_rms`, or k_s comes out below `min_ks`, the cluster
// is declared diffuse (k_s = 0).
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "relight/brdf/shading.h"
#include "relight/core/image.h"

namespace relight::brdf {

struct SpecularSample {
  Eigen::Vector3f radiance;  ///< linear RGB as observed (not highlight-cleaned), unclipped
  Eigen::Vector3f position;  ///< camera frame, metres
  Eigen::Vector3f normal;    ///< camera frame, unit
};

struct SpecularProblem {
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();
  std::vector<SpecularSample> samples;
  ShadingLights lights;
};

/// A starting point of the (k_s, n) fit.
struct SpecularStart {
  float ks = 0.f;
  float n = 1.f;
};

struct SpecularOptions {
  float ks_max = 1.f;
  float n_min = 1.f;
  float n_max = 1000.f;
  /// The fits start from the best of this many exponents spaced evenly in log n over
  /// [n_min, n_max], each with its least-squares k_s (for fixed n the model is linear in k_s).
  int start_exponents = 12;
  /// When set, the fits start here instead of from that grid (SpecularFitStage on Vulkan: the
  /// best of a denser (k_s, n) grid evaluated on the GPU, specular_objective_vk.h).
  std::optional<SpecularStart> start;
  /// How many of the strongest lights may move (at most 2); 0 keeps every light fixed.
  int moving_lights = 2;
  float point_offset_max = 0.05f;      ///< metres, per axis, for point lights
  float direction_offset_max = 0.05f;  ///< per component of a directional light's unit vector
  float max_rms = 0.05f;               ///< radiance units; above it the cluster is diffuse
  float min_ks = 1e-3f;
  int max_evaluations = 2000;          ///< Nelder-Mead evaluations per (k_s, n) phase
  int light_evaluations = 600;         ///< Nelder-Mead evaluations of the light phase
  /// Nelder-Mead moves the lights only when the fit with fixed lights leaves an RMS residual
  /// above this (about one 8-bit step at mid grey) and the cluster is not diffuse.
  float light_refine_rms = 0.004f;
  int max_iterations = 30;             ///< Ceres iterations per solve
};

struct SpecularFit {
  float ks = 0.f;
  float n = 1.f;
  bool specular = false;                     ///< false: declared diffuse (ks set to 0)
  double rms = 0.0;                          ///< RMS residual per channel at the optimum
  double objective = 0.0;                    ///< F at the optimum (before the diffuse decision)
  std::vector<Eigen::Vector3f> light_offsets;  ///< per moving light, in the problem's light order
  int evaluations = 0;                       ///< objective evaluations (NM) or iterations (Ceres)
};

class SpecularSolver {
 public:
  virtual ~SpecularSolver() = default;
  [[nodiscard]] virtual std::string name() const = 0;
  [[nodiscard]] virtual SpecularFit fit(const SpecularProblem& problem, const SpecularOptions& options) const = 0;
};

[[nodiscard]] std::unique_ptr<SpecularSolver> make_nelder_mead_solver();
[[nodiscard]] std::unique_ptr<SpecularSolver> make_ceres_solver();

/// F for given parameters (offsets: one per moving light, may be empty), for tests.
[[nodiscard]] double specular_objective(const SpecularProblem& problem, const SpecularOptions& options, float ks,
                                        float n, const std::vector<Eigen::Vector3f>& offsets = {});

/// Indices of the lights that move, strongest (luminance of power) first.
[[nodiscard]] std::vector<int> moving_light_indices(const ShadingLights& lights, int moving);

/// Picks at most `max_samples` pixels of `cluster` (ids hold cluster + 1): every pixel of
/// `highlights` first (up to half the budget), the rest on an even stride through the cluster's
/// pixels in row-major order (stratified over the image). Pixels whose 8-bit colour is clipped
/// (a channel >= 254) or that lack position/normal are skipped: they do not show the model's value.
[[nodiscard]] std::vector<SpecularSample> select_samples(const ColorImage& color, const PositionMap& positions,
                                                         const NormalMap& normals, const LabelImage& ids, int cluster,
                                                         const Mask* highlights, int max_samples = 2048);

/// select_samples() for clusters 0 .. clusters - 1 at once, in one pass over the image.
[[nodiscard]] std::vector<std::vector<SpecularSample>> select_cluster_samples(
    const ColorImage& color, const PositionMap& positions, const NormalMap& normals, const LabelImage& ids,
    int clusters, const Mask* highlights, int max_samples = 2048);

}  // namespace relight::brdf
