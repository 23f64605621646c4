// Specular fit: shared pieces and the Nelder-Mead solver (specular_fit.h).
#include "relight/brdf/specular_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "relight/core/error.h"
#include "specular_model.h"

namespace relight::brdf {

namespace {

double luminance(const Eigen::Vector3f& v) { return 0.2126 * v.x() + 0.7152 * v.y() + 0.0722 * v.z(); }

/// Box bounds of the parameter vector x = (k_s, log n, offsets...).
struct Bounds {
  std::vector<double> lower, upper;
};

Bounds bounds_for(const ShadingLights& ordered, int moving, const SpecularOptions& options) {
  Bounds b;
  b.lower = {0.0, std::log(static_cast<double>(options.n_min))};
  b.upper = {static_cast<double>(options.ks_max), std::log(static_cast<double>(options.n_max))};
  for (int l = 0; l < moving; ++l) {
    const double d = ordered.lights[static_cast<std::size_t>(l)].point ? options.point_offset_max
                                                                      : options.direction_offset_max;
    for (int c = 0; c < 3; ++c) {
      b.lower.push_back(-d);
      b.upper.push_back(d);
    }
  }
  return b;
}

double objective_ordered(const SpecularProblem& problem, const ShadingLights& ordered, int moving, double ks, double n,
                         const double* offsets) {
  std::array<const double*, 2> offset_ptrs{offsets, offsets ? offsets + 3 : nullptr};
  double sum = 0.0;
  for (const SpecularSample& s : problem.samples) {
    double model[3];
    detail::model_radiance<double>(s, problem.kd, ordered, ks, n, offset_ptrs.data(), moving, model);
    for (int c = 0; c < 3; ++c) {
      const double r = static_cast<double>(s.radiance[c]) - model[c];
      sum += r * r;
    }
  }
  return sum;
}

void finish(SpecularFit& fit, const SpecularProblem& problem, const SpecularOptions& options) {
  const double residuals = 3.0 * static_cast<double>(std::max<std::size_t>(1, problem.samples.size()));
  fit.rms = std::sqrt(fit.objective / residuals);
  fit.specular = fit.rms <= options.max_rms && fit.ks >= options.min_ks && !problem.samples.empty();
  if (!fit.specular) fit.ks = 0.f;
}

class NelderMeadSolver final : public SpecularSolver {
 public:
  [[nodiscard]] std::string name() const override { return "nelder_mead"; }

  [[nodiscard]] SpecularFit fit(const SpecularProblem& problem, const SpecularOptions& options) const override {
    const std::vector<int> moving_ids = moving_light_indices(problem.lights, options.moving_lights);
    const int moving = static_cast<int>(moving_ids.size());
    const ShadingLights ordered = detail::moving_first(problem.lights, moving_ids);
    const Bounds bounds = bounds_for(ordered, moving, options);
    const std::size_t dims = bounds.lower.size();
    int evaluations = 0;
    auto clamp = [&](std::vector<double>& x) {
      for (std::size_t i = 0; i < dims; ++i) x[i] = std::clamp(x[i], bounds.lower[i], bounds.upper[i]);
    };
    auto f = [&](const std::vector<double>& x) {
      ++evaluations;
      return objective_ordered(problem, ordered, moving, x[0], std::exp(x[1]), dims > 2 ? x.data() + 2 : nullptr);
    };
    std::vector<double> start(dims, 0.0);
    start[0] = options.ks_start;
    start[1] = std::log(static_cast<double>(options.n_start));
    clamp(start);
    std::vector<double> steps(dims);
    steps[0] = 0.25 * options.ks_max;
    steps[1] = 0.7;
    for (std::size_t i = 2; i < dims; ++i) steps[i] = 0.5 * bounds.upper[i];

    std::vector<double> best = start;
    double best_f = f(best);
    for (int restart = 0; restart < 4 && evaluations < options.max_evaluations; ++restart) {
      const double before = best_f;
      minimise(f, clamp, best, best_f, steps, options.max_evaluations, evaluations);
      if (restart > 0 && before - best_f <= 1e-9 * std::max(1.0, before)) break;
      for (double& s : steps) s *= 0.5;  // restarts search closer to the optimum
    }
    SpecularFit fit;
    fit.ks = static_cast<float>(best[0]);
    fit.n = static_cast<float>(std::exp(best[1]));
    fit.objective = best_f;
    fit.evaluations = evaluations;
    for (int l = 0; l < moving; ++l) {
      fit.light_offsets.emplace_back(static_cast<float>(best[2 + 3 * l]), static_cast<float>(best[3 + 3 * l]),
                                     static_cast<float>(best[4 + 3 * l]));
    }
    finish(fit, problem, options);
    return fit;
  }

 private:
  // One Nelder-Mead run (reflection 1, expansion 2, contraction 1/2, shrink 1/2) from `x` with
  // the given initial steps; every vertex is projected onto the bounds.
  template <class F, class Clamp>
  static void minimise(F& f, Clamp& clamp, std::vector<double>& x, double& fx, const std::vector<double>& steps,
                       int max_evaluations, int& evaluations) {
    const std::size_t dims = x.size();
    std::vector<std::vector<double>> simplex(dims + 1, x);
    std::vector<double> values(dims + 1, fx);
    for (std::size_t i = 0; i < dims; ++i) {
      simplex[i + 1][i] += steps[i];
      clamp(simplex[i + 1]);
      if (simplex[i + 1][i] == x[i]) {  // at a bound: step the other way
        simplex[i + 1][i] -= steps[i];
        clamp(simplex[i + 1]);
      }
      values[i + 1] = f(simplex[i + 1]);
    }
    std::vector<std::size_t> order(dims + 1);
    std::vector<double> centroid(dims), trial(dims), trial2(dims);
    while (evaluations < max_evaluations) {
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
      const std::size_t best = order.front(), worst = order.back(), second = order[dims - 1];
      if (values[worst] - values[best] <= 1e-10 * std::max(1e-12, std::abs(values[best]))) break;
      double size = 0.0;
      for (std::size_t i = 0; i < dims; ++i) size = std::max(size, std::abs(simplex[worst][i] - simplex[best][i]));
      if (size < 1e-7) break;
      std::fill(centroid.begin(), centroid.end(), 0.0);
      for (std::size_t v = 0; v <= dims; ++v) {
        if (v == worst) continue;
        for (std::size_t i = 0; i < dims; ++i) centroid[i] += simplex[v][i] / static_cast<double>(dims);
      }
      auto along = [&](double t, std::vector<double>& out) {
        for (std::size_t i = 0; i < dims; ++i) out[i] = centroid[i] + t * (simplex[worst][i] - centroid[i]);
        clamp(out);
        return f(out);
      };
      const double fr = along(-1.0, trial);
      if (fr < values[best]) {
        const double fe = along(-2.0, trial2);
        if (fe < fr) {
          simplex[worst] = trial2;
          values[worst] = fe;
        } else {
          simplex[worst] = trial;
          values[worst] = fr;
        }
      } else if (fr < values[second]) {
        simplex[worst] = trial;
        values[worst] = fr;
      } else {
        const bool outside = fr < values[worst];
        const double fc = along(outside ? -0.5 : 0.5, trial2);
        if (fc < (outside ? fr : values[worst])) {
          simplex[worst] = trial2;
          values[worst] = fc;
        } else {
          for (std::size_t v = 0; v <= dims; ++v) {
            if (v == best) continue;
            for (std::size_t i = 0; i < dims; ++i) simplex[v][i] = simplex[best][i] + 0.5 * (simplex[v][i] - simplex[best][i]);
            clamp(simplex[v]);
            values[v] = f(simplex[v]);
          }
        }
      }
    }
    const auto best = static_cast<std::size_t>(std::min_element(values.begin(), values.end()) - values.begin());
    if (values[best] < fx) {
      x = simplex[best];
      fx = values[best];
    }
  }
};

}  // namespace

std::vector<int> moving_light_indices(const ShadingLights& lights, int moving) {
  std::vector<int> order(lights.lights.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return luminance(lights.lights[static_cast<std::size_t>(a)].power) >
           luminance(lights.lights[static_cast<std::size_t>(b)].power);
  });
  order.resize(static_cast<std::size_t>(std::clamp(moving, 0, std::min(2, static_cast<int>(order.size())))));
  return order;
}

double specular_objective(const SpecularProblem& problem, const SpecularOptions& options, float ks, float n,
                          const std::vector<Eigen::Vector3f>& offsets) {
  const std::vector<int> moving_ids =
      moving_light_indices(problem.lights, std::min<int>(options.moving_lights, static_cast<int>(offsets.size())));
  const int moving = static_cast<int>(moving_ids.size());
  const ShadingLights ordered = detail::moving_first(problem.lights, moving_ids);
  std::vector<double> flat;
  for (int l = 0; l < moving; ++l) {
    for (int c = 0; c < 3; ++c) flat.push_back(offsets[static_cast<std::size_t>(l)][c]);
  }
  return objective_ordered(problem, ordered, moving, ks, n, flat.empty() ? nullptr : flat.data());
}

std::vector<SpecularSample> select_samples(const ColorImage& color, const PositionMap& positions,
                                           const NormalMap& normals, const LabelImage& ids, int cluster,
                                           const Mask* highlights, int max_samples) {
  if (!color.same_shape(positions) || !color.same_shape(normals) || !color.same_shape(ids)) {
    throw Error("brdf specular: colour, positions, normals and cluster ids must have the same size");
  }
  const auto label = static_cast<std::uint16_t>(cluster + 1);
  std::vector<std::uint32_t> plain, bright;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids.pixels()[i] != label) continue;
    const Rgb8 c = color.pixels()[i];
    if (std::max({c.r, c.g, c.b}) >= 254) continue;
    if (!is_valid_normal(normals.pixels()[i]) || !is_valid_depth(positions.pixels()[i].z)) continue;
    (highlights && highlights->pixels()[i] ? bright : plain).push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<std::uint32_t> chosen;
  const auto budget = static_cast<std::size_t>(std::max(0, max_samples));
  auto take_strided = [&](const std::vector<std::uint32_t>& from, std::size_t count) {
    if (from.size() <= count) {
      chosen.insert(chosen.end(), from.begin(), from.end());
      return;
    }
    for (std::size_t k = 0; k < count; ++k) chosen.push_back(from[k * from.size() / count]);
  };
  take_strided(bright, budget / 2);
  take_strided(plain, budget - chosen.size());
  std::vector<SpecularSample> samples;
  samples.reserve(chosen.size());
  for (const std::uint32_t i : chosen) {
    const Rgb8 c = color.pixels()[i];
    const Float3 p = positions.pixels()[i], n = normals.pixels()[i];
    samples.push_back({{srgb8_to_linear(c.r), srgb8_to_linear(c.g), srgb8_to_linear(c.b)}, {p.x, p.y, p.z}, {n.x, n.y, n.z}});
  }
  return samples;
}

std::unique_ptr<SpecularSolver> make_nelder_mead_solver() { return std::make_unique<NelderMeadSolver>(); }

namespace detail {
void finish_fit(SpecularFit& fit, const SpecularProblem& problem, const SpecularOptions& options) {
  finish(fit, problem, options);
}
}  // namespace detail

}  // namespace relight::brdf
