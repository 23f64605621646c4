// Specular fit with Ceres (specular_fit.h): one AutoDiffCostFunction per sample.
#include <ceres/ceres.h>

#include <algorithm>
#include <array>

#include "relight/brdf/specular_fit.h"
#include "specular_model.h"

namespace relight::brdf {

namespace detail {
void finish_fit(SpecularFit& fit, const SpecularProblem& problem, const SpecularOptions& options);
}  // namespace detail

namespace {

/// Residual of one sample: observed minus model, 3 channels. Blocks: (k_s, n), offset of moving
/// light 0, offset of moving light 1 (an unused block is held constant at zero).
struct SampleResidual {
  const SpecularSample* sample;
  const Eigen::Vector3f* kd;
  const ShadingLights* lights;
  int moving;

  template <class T>
  bool operator()(const T* shape, const T* offset0, const T* offset1, T* residual) const {
    const std::array<const T*, 2> offsets{offset0, offset1};
    T model[3];
    detail::model_radiance<T>(*sample, *kd, *lights, shape[0], shape[1], offsets.data(), moving, model);
    for (int c = 0; c < 3; ++c) residual[c] = T(double(sample->radiance[c])) - model[c];
    return true;
  }
};

class CeresSolver final : public SpecularSolver {
 public:
  [[nodiscard]] std::string name() const override { return "ceres"; }

  [[nodiscard]] SpecularFit fit(const SpecularProblem& problem, const SpecularOptions& options) const override {
    const std::vector<int> moving_ids = moving_light_indices(problem.lights, options.moving_lights);
    const int moving = static_cast<int>(moving_ids.size());
    const ShadingLights ordered = detail::moving_first(problem.lights, moving_ids);
    double shape[2] = {std::clamp<double>(options.ks_start, 0.0, options.ks_max),
                       std::clamp<double>(options.n_start, options.n_min, options.n_max)};
    double offsets[2][3] = {{0, 0, 0}, {0, 0, 0}};
    ceres::Problem cp;
    for (const SpecularSample& s : problem.samples) {
      auto* cost = new ceres::AutoDiffCostFunction<SampleResidual, 3, 2, 3, 3>(
          new SampleResidual{&s, &problem.kd, &ordered, moving});
      cp.AddResidualBlock(cost, nullptr, shape, offsets[0], offsets[1]);
    }
    SpecularFit fit;
    if (problem.samples.empty()) {
      detail::finish_fit(fit, problem, options);
      return fit;
    }
    cp.SetParameterLowerBound(shape, 0, 0.0);
    cp.SetParameterUpperBound(shape, 0, options.ks_max);
    cp.SetParameterLowerBound(shape, 1, options.n_min);
    cp.SetParameterUpperBound(shape, 1, options.n_max);
    for (int l = 0; l < 2; ++l) {
      if (l >= moving) {
        cp.SetParameterBlockConstant(offsets[l]);
        continue;
      }
      const double d = ordered.lights[static_cast<std::size_t>(l)].point ? options.point_offset_max
                                                                        : options.direction_offset_max;
      for (int c = 0; c < 3; ++c) {
        cp.SetParameterLowerBound(offsets[l], c, -d);
        cp.SetParameterUpperBound(offsets[l], c, d);
      }
    }
    ceres::Solver::Options so;
    so.minimizer_type = ceres::TRUST_REGION;
    so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = options.max_iterations;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &cp, &summary);
    fit.ks = static_cast<float>(shape[0]);
    fit.n = static_cast<float>(shape[1]);
    fit.objective = 2.0 * summary.final_cost;  // Ceres minimises half the sum of squares
    fit.evaluations = static_cast<int>(summary.iterations.size());
    for (int l = 0; l < moving; ++l) {
      fit.light_offsets.emplace_back(static_cast<float>(offsets[l][0]), static_cast<float>(offsets[l][1]),
                                     static_cast<float>(offsets[l][2]));
    }
    detail::finish_fit(fit, problem, options);
    return fit;
  }
};

}  // namespace

std::unique_ptr<SpecularSolver> make_ceres_solver() { return std::make_unique<CeresSolver>(); }

}  // namespace relight::brdf
