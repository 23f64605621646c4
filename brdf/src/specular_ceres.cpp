// Specular fit with Ceres (specular_fit.h): one AutoDiffCostFunction per sample.
#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <vector>

#include "relight/brdf/specular_fit.h"
#include "specular_model.h"
#include "specular_terms.h"

namespace relight::brdf {

namespace detail {
void finish_fit(SpecularFit& fit, const SpecularProblem& problem, const SpecularOptions& options);
}  // namespace detail

namespace {

/// Residuals of the light phase's samples (observed minus model, 3 channels each) in one block
/// per parameter group: (k_s, n), offset of moving light 0, offset of moving light 1 (an unused
/// block is held constant at zero).
struct SubsetResidual {
  const std::vector<SpecularSample>* samples;
  const Eigen::Vector3f* kd;
  const ShadingLights* lights;
  int moving;

  template <class T>
  bool operator()(const T* shape, const T* offset0, const T* offset1, T* residual) const {
    const std::array<const T*, 2> offsets{offset0, offset1};
    for (const SpecularSample& sample : *samples) {
      T model[3];
      detail::model_radiance<T>(sample, *kd, *lights, shape[0], shape[1], offsets.data(), moving, model);
      for (int c = 0; c < 3; ++c) *residual++ = T(double(sample.radiance[c])) - model[c];
    }
    return true;
  }
};

/// Ends the light phase after `probe` iterations that lowered the cost by less than 10 %: the
/// misfit has another cause (shadows, mixed materials) than misplaced lights (as Nelder-Mead's
/// probe).
class LightProbe final : public ceres::IterationCallback {
 public:
  explicit LightProbe(int probe) : probe_(probe) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration == 0) initial_ = summary.cost;
    if (summary.iteration == probe_ && summary.cost > 0.9 * initial_) return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    return ceres::SOLVER_CONTINUE;
  }

 private:
  int probe_;
  double initial_ = 0.0;
};

/// Every residual with the lights fixed, in one block over (k_s, n) with the analytic Jacobian
/// of detail::ShapeTerms: a residual block per sample would cost Ceres more bookkeeping than the
/// model itself.
class ShapeCost final : public ceres::CostFunction {
 public:
  explicit ShapeCost(const detail::ShapeTerms& terms) : terms_(terms) {
    set_num_residuals(static_cast<int>(3 * terms.samples()));
    mutable_parameter_block_sizes()->push_back(2);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    terms_.residuals(parameters[0][0], parameters[0][1], residuals, jacobians ? jacobians[0] : nullptr);
    return true;
  }

 private:
  const detail::ShapeTerms& terms_;
};

ceres::Solver::Options solver_options(const SpecularOptions& options) {
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.num_threads = 1;
  return so;
}

void bound_shape(ceres::Problem& cp, double* shape, const SpecularOptions& options) {
  cp.SetParameterLowerBound(shape, 0, 0.0);
  cp.SetParameterUpperBound(shape, 0, options.ks_max);
  cp.SetParameterLowerBound(shape, 1, options.n_min);
  cp.SetParameterUpperBound(shape, 1, options.n_max);
}

constexpr std::size_t kLightSamples = 128;
constexpr int kLightProbeIterations = 5;
constexpr double kLightFunctionTolerance = 1e-4;

/// (k_s, n) with the lights fixed; returns F (Ceres minimises half of it). A negative shape[0]
/// starts from detail::start_shape().
double solve_shape(const SpecularProblem& problem, const ShadingLights& lights, const SpecularOptions& options,
                   const ceres::Solver::Options& so, double* shape, int& iterations) {
  const detail::ShapeTerms terms(problem, lights);
  if (shape[0] < 0.0) {
    const detail::StartShape start = detail::start_shape(terms, options);
    shape[0] = start.ks;
    shape[1] = start.n;
  }
  ShapeCost cost(terms);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem cp(po);
  cp.AddResidualBlock(&cost, nullptr, shape);
  bound_shape(cp, shape, options);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &cp, &summary);
  iterations += static_cast<int>(summary.iterations.size());
  return 2.0 * summary.final_cost;
}

class CeresSolver final : public SpecularSolver {
 public:
  [[nodiscard]] std::string name() const override { return "ceres"; }

  // Phase 1 fits (k_s, n) with the lights fixed; like Nelder-Mead, the lights move (phase 2,
  // every parameter, from phase 1's optimum) only when the residual stays above
  // light_refine_rms and the cluster is not diffuse.
  [[nodiscard]] SpecularFit fit(const SpecularProblem& problem, const SpecularOptions& options) const override {
    const std::vector<int> moving_ids = moving_light_indices(problem.lights, options.moving_lights);
    const int moving = static_cast<int>(moving_ids.size());
    const ShadingLights ordered = detail::moving_first(problem.lights, moving_ids);
    SpecularFit fit;
    if (problem.samples.empty()) {
      detail::finish_fit(fit, problem, options);
      return fit;
    }
    double shape[2] = {-1.0, 0.0};  // from detail::start_shape()
    double offsets[2][3] = {{0, 0, 0}, {0, 0, 0}};
    const ceres::Solver::Options so = solver_options(options);
    int iterations = 0;
    double objective = solve_shape(problem, ordered, options, so, shape, iterations);
    const double residuals = 3.0 * static_cast<double>(problem.samples.size());
    const bool refine = moving > 0 && shape[0] >= options.min_ks &&
                        std::sqrt(objective / residuals) > options.light_refine_rms;
    if (refine) {
      // Phase 2 on a strided subset (the offsets are few and smooth), phase 3: (k_s, n) on all
      // samples with the moved lights; kept if F drops.
      double shape2[2] = {shape[0], shape[1]};
      double offsets2[2][3] = {{0, 0, 0}, {0, 0, 0}};
      std::vector<SpecularSample> subset;
      const std::size_t stride = problem.samples.size() / kLightSamples + 1;
      for (std::size_t i = 0; i < problem.samples.size(); i += stride) subset.push_back(problem.samples[i]);
      ceres::AutoDiffCostFunction<SubsetResidual, ceres::DYNAMIC, 2, 3, 3> cost(
          new SubsetResidual{&subset, &problem.kd, &ordered, moving}, static_cast<int>(3 * subset.size()));
      ceres::Problem::Options po;
      po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      ceres::Problem cp(po);
      cp.AddResidualBlock(&cost, nullptr, shape2, offsets2[0], offsets2[1]);
      bound_shape(cp, shape2, options);
      for (int l = 0; l < 2; ++l) {
        if (l >= moving) {
          cp.SetParameterBlockConstant(offsets2[l]);
          continue;
        }
        const double d = ordered.lights[static_cast<std::size_t>(l)].point ? options.point_offset_max
                                                                          : options.direction_offset_max;
        for (int c = 0; c < 3; ++c) {
          cp.SetParameterLowerBound(offsets2[l], c, -d);
          cp.SetParameterUpperBound(offsets2[l], c, d);
        }
      }
      LightProbe probe(kLightProbeIterations);
      ceres::Solver::Options light_options = so;
      light_options.callbacks.push_back(&probe);
      // The light phase only has to find where the lights go; the shape fit after it polishes.
      light_options.function_tolerance = kLightFunctionTolerance;
      ceres::Solver::Summary summary;
      ceres::Solve(light_options, &cp, &summary);
      iterations += static_cast<int>(summary.iterations.size());
      ShadingLights moved = ordered;
      for (int l = 0; l < moving; ++l) {
        for (int c = 0; c < 3; ++c) moved.lights[static_cast<std::size_t>(l)].vector[c] += static_cast<float>(offsets2[l][c]);
      }
      const double objective3 = solve_shape(problem, moved, options, so, shape2, iterations);
      if (objective3 < objective) {
        objective = objective3;
        std::copy(shape2, shape2 + 2, shape);
        std::copy(&offsets2[0][0], &offsets2[0][0] + 6, &offsets[0][0]);
      }
    }
    fit.ks = static_cast<float>(shape[0]);
    fit.n = static_cast<float>(shape[1]);
    fit.objective = objective;
    fit.evaluations = iterations;
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
