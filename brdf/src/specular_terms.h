#pragma once
// The specular objective F (specular_fit.h, eq. 4.15) over all samples at once, as Eigen arrays
// in structure-of-arrays layout, so that exp, log and sqrt run vectorised (Eigen's packet math,
// double precision) instead of once per sample through the scalar model of specular_model.h.
// Both forms compute the same expression as detail::model_radiance<double>. Private to
// relight_brdf.
//
// ShapeTerms: the lights fixed. Then per sample i and light l the irradiance E_l(i) (cosine
// included, zero where the light is behind the surface or its mirror lobe misses the camera) and
// g_l(i) = log<omega_o . r_l> are constants, and
//
//   r_c(i) = b_c(i) - k_s (n + 2) / (2 pi) * sum_l E_l,c(i) exp(n g_l(i))
//
// with b the observation minus the diffuse part. F(k_s, n) costs one exp per sample and light,
// and for fixed n the best k_s is a linear least-squares solution (variable projection), which
// gives the solvers a starting point close to the optimum. The samples are kept ordered by
// their widest lobe, so that an evaluation at exponent n touches only the prefix whose lobes are
// not negligible (exp(n g) > 1e-20): glossy exponents skip most samples.
//
// FullModel: every parameter free (lights moved by offsets), for the light phase. It works in
// float (four samples per SSE packet instead of two): the light phase only needs to find where
// the lights go, and the shape fit that follows it recomputes F in double.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "relight/brdf/specular_fit.h"

namespace relight::brdf::detail {

class ShapeTerms {
 public:
  /// Terms of `problem`'s samples under `lights` (already moved where they should be).
  ShapeTerms(const SpecularProblem& problem, const ShadingLights& lights);

  [[nodiscard]] Eigen::Index samples() const { return base_[0].size(); }
  /// F(k_s, n).
  [[nodiscard]] double objective(double ks, double n) const;
  /// The k_s in [0, ks_max] minimising F for this n, and F there.
  struct Projected {
    double ks;
    double objective;
  };
  [[nodiscard]] Projected best_ks(double n, double ks_max) const;
  /// Residuals r_c(i) (3 per sample, sample-major) and, when `jacobian` is not null, their
  /// derivatives by (k_s, n), row-major (2 per residual).
  void residuals(double ks, double n, double* residuals, double* jacobian) const;

 private:
  struct Lobe {
    std::array<Eigen::ArrayXd, 3> irradiance;
    Eigen::ArrayXd log_rv;
  };
  /// Orders the samples by their widest lobe (largest g_l), widest first, and sums b^2 over
  /// every tail of that order.
  void sort_by_lobe();
  /// How many samples (a prefix of that order) have a lobe that is not negligible at exponent n.
  [[nodiscard]] Eigen::Index lit_samples(double n) const;
  /// sum_l E_l,c exp(n g_l) per channel (and sum_l E_l,c g_l exp(n g_l) when `slope`) of the
  /// first `lit` samples.
  void lobe_sums(double n, Eigen::Index lit, std::array<Eigen::ArrayXd, 3>& sums,
                 std::array<Eigen::ArrayXd, 3>* slope) const;

  std::array<Eigen::ArrayXd, 3> base_;
  std::vector<Lobe> lobes_;
  std::vector<double> widest_;  // per sample (sorted, descending): the largest g_l of a lobe
  std::vector<double> tail_bb_;  // sum of b^2 over samples i.. of the sorted order
};

/// The lights with the first `moving` moved by offsets[3 l .. 3 l + 2] (null: none moved).
[[nodiscard]] ShadingLights moved_lights(const ShadingLights& ordered, int moving, const double* offsets);

/// Starting point of a (k_s, n) fit: options.start when set, else the best of
/// options.start_exponents exponents spaced evenly in log n over [n_min, n_max], each with its
/// least-squares k_s.
struct StartShape {
  double ks = 0.0;
  double n = 1.0;
  double log_n_spacing = 0.0;
  int evaluations = 0;
};
[[nodiscard]] StartShape start_shape(const ShapeTerms& terms, const SpecularOptions& options);
/// `count` (at least 2) exponents spaced evenly in log n over [n_min, n_max]: the grid of
/// start_shape() (count = options.start_exponents) and of the GPU start (specular_start_grid()).
[[nodiscard]] std::vector<double> log_spaced_exponents(const SpecularOptions& options, int count);
/// Only the grid's log n spacing (no evaluations).
[[nodiscard]] StartShape start_shape_spacing(const SpecularOptions& options);

class FullModel {
 public:
  /// `ordered`: the lights with the `moving` ones first (moving_first()).
  FullModel(const SpecularProblem& problem, const ShadingLights& ordered, int moving);
  /// F with the first `moving` lights moved by offsets[3 l .. 3 l + 2].
  [[nodiscard]] double objective(double ks, double n, const double* offsets);

 private:
  Eigen::Vector3f kd_, ambient_;
  ShadingLights lights_;
  int moving_;
  Eigen::ArrayXf px_, py_, pz_, nx_, ny_, nz_, vx_, vy_, vz_, n_dot_v_;
  std::array<Eigen::ArrayXf, 3> radiance_;
  // Scratch of objective().
  Eigen::ArrayXf dx_, dy_, dz_, inv_d_, cosine_, rv_, irradiance_, lobe_;
  std::array<Eigen::ArrayXf, 3> model_;
};

}  // namespace relight::brdf::detail
