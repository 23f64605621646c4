// Specular fit: shared pieces and the Nelder-Mead solver (specular_fit.h).
#include "relight/brdf/specular_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>

#include "relight/core/error.h"
#include "specular_model.h"
#include "specular_terms.h"

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
    int evaluations = 0;
    const Bounds shape_bounds{{bounds.lower[0], bounds.lower[1]}, {bounds.upper[0], bounds.upper[1]}};

    // Phase A: (k_s, log n) with the lights where they are (detail::ShapeTerms), from the best
    // exponent of a coarse grid with its least-squares k_s.
    std::vector<double> offsets(static_cast<std::size_t>(3 * moving), 0.0);
    std::vector<double> shape;
    double best_f = fit_shape(problem, ordered, moving, offsets, shape_bounds, options, shape, evaluations);

    const double residuals = 3.0 * static_cast<double>(std::max<std::size_t>(1, problem.samples.size()));
    const bool diffuse = shape[0] < options.min_ks;
    const bool explained = std::sqrt(best_f / residuals) <= options.light_refine_rms;
    if (moving > 0 && !diffuse && !explained) {
      // Phase B: every parameter, on a strided subset (the light offsets are few and smooth).
      SpecularProblem subset;
      subset.kd = problem.kd;
      subset.lights = problem.lights;
      const std::size_t stride = problem.samples.size() / kLightSamples + 1;
      for (std::size_t i = 0; i < problem.samples.size(); i += stride) subset.samples.push_back(problem.samples[i]);
      std::vector<double> x = shape;
      x.insert(x.end(), offsets.begin(), offsets.end());
      auto clamp = [&](std::vector<double>& v) {
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::clamp(v[i], bounds.lower[i], bounds.upper[i]);
      };
      detail::FullModel model(subset, ordered, moving);
      auto f = [&](const std::vector<double>& v) {
        ++evaluations;
        return model.objective(v[0], std::exp(v[1]), v.data() + 2);
      };
      std::vector<double> steps(x.size());
      steps[0] = 0.05 * options.ks_max;
      steps[1] = 0.1;
      for (std::size_t i = 2; i < x.size(); ++i) steps[i] = 0.5 * bounds.upper[i];
      double fx = f(x);
      // A short probe first: when moving the lights buys less than 10 % of F, the misfit has
      // another cause (shadows, mixed materials) and the rest of the budget is not spent.
      const double f_start = fx;
      const int budget_end = evaluations + options.light_evaluations;
      restarts(f, clamp, x, fx, steps, std::min(budget_end, evaluations + kLightProbe), evaluations);
      if (fx < 0.9 * f_start) restarts(f, clamp, x, fx, steps, budget_end, evaluations);
      // Phase C: (k_s, log n) again on all samples with the moved lights; kept if F drops.
      std::vector<double> moved(x.begin() + 2, x.end());
      std::vector<double> shape_c(x.begin(), x.begin() + 2);
      const double f_c = fit_shape(problem, ordered, moving, moved, shape_bounds, options, shape_c, evaluations);
      if (f_c < best_f) {
        best_f = f_c;
        shape = shape_c;
        offsets = moved;
      }
    }
    SpecularFit fit;
    fit.ks = static_cast<float>(shape[0]);
    fit.n = static_cast<float>(std::exp(shape[1]));
    fit.objective = best_f;
    fit.evaluations = evaluations;
    for (int l = 0; l < moving; ++l) {
      const auto o = static_cast<std::size_t>(3 * l);
      fit.light_offsets.emplace_back(static_cast<float>(offsets[o]), static_cast<float>(offsets[o + 1]),
                                     static_cast<float>(offsets[o + 2]));
    }
    finish(fit, problem, options);
    return fit;
  }

 private:
  static constexpr std::size_t kLightSamples = 256;
  static constexpr int kLightProbe = 150;
  // The light phase's simplex has converged at this size: 1 mm of light offset, 0.1 % of n, and
  // in k_s below what 8-bit data resolve; the shape fit that follows polishes k_s and n.
  static constexpr double kLightSimplexSize = 1e-3;
  // The shape fit's (log n) simplex: one dimension halves cheaply, and noise-free data leave F
  // near zero, where a coarser n would still show.
  static constexpr double kShapeSimplexSize = 1e-6;
  // A restart that lowers F by less than this fraction ends the restarts.
  static constexpr double kRestartGain = 1e-6;

  /// Restarted Nelder-Mead: fresh simplices of halving size from the best vertex until a restart
  /// no longer improves F.
  template <class F, class Clamp>
  static void restarts(F& f, Clamp& clamp, std::vector<double>& x, double& fx, std::vector<double> steps,
                       int max_evaluations, int& evaluations) {
    for (int restart = 0; restart < 4 && evaluations < max_evaluations; ++restart) {
      const double before = fx;
      minimise(f, clamp, x, fx, steps, kLightSimplexSize, max_evaluations, evaluations);
      if (restart > 0 && before - fx <= kRestartGain * before) break;
      for (double& step : steps) step *= 0.5;
    }
  }

  /// Fits (k_s, log n) with the lights fixed at `offsets`; returns F on all samples. For fixed
  /// lights and n the model is linear in k_s, so the simplex searches log n alone and every
  /// vertex takes its least-squares k_s in [0, ks_max] (variable projection: the same minimum as
  /// over both, in far fewer evaluations). Starts from detail::start_shape(), or from `shape`
  /// when given.
  static double fit_shape(const SpecularProblem& problem, const ShadingLights& ordered, int moving,
                          const std::vector<double>& offsets, const Bounds& bounds, const SpecularOptions& options,
                          std::vector<double>& shape, int& evaluations) {
    const detail::ShapeTerms terms(problem, detail::moved_lights(ordered, moving, offsets.data()));
    // From phase B's optimum the simplex starts at the grid's spacing without the grid.
    detail::StartShape start;
    if (shape.empty()) {
      start = detail::start_shape(terms, options);
      evaluations += start.evaluations;
    } else {
      start = detail::start_shape_spacing(options);
      start.n = std::exp(shape[1]);
    }
    std::vector<double> log_n{std::log(start.n)};
    auto clamp = [&](std::vector<double>& v) { v[0] = std::clamp(v[0], bounds.lower[1], bounds.upper[1]); };
    auto f = [&](const std::vector<double>& v) {
      ++evaluations;
      return terms.best_ks(std::exp(v[0]), options.ks_max).objective;
    };
    double fx = f(log_n);
    // The grid brackets the minimum within one spacing. One run: restarts guard against a
    // simplex that collapses onto a subspace, which a one-dimensional simplex cannot.
    minimise(f, clamp, log_n, fx, {0.5 * start.log_n_spacing}, kShapeSimplexSize,
             evaluations + options.max_evaluations, evaluations);
    shape = {terms.best_ks(std::exp(log_n[0]), options.ks_max).ks, log_n[0]};
    return fx;
  }

  // One Nelder-Mead run (reflection 1, expansion 2, contraction 1/2, shrink 1/2) from `x` with
  // the given initial steps, until the simplex is smaller than `min_size` in every coordinate;
  // every vertex is projected onto the bounds.
  template <class F, class Clamp>
  static void minimise(F& f, Clamp& clamp, std::vector<double>& x, double& fx, const std::vector<double>& steps,
                       double min_size, int max_evaluations, int& evaluations) {
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
      if (size < min_size) break;
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

std::vector<std::vector<SpecularSample>> select_cluster_samples(const ColorImage& color, const PositionMap& positions,
                                                                const NormalMap& normals, const LabelImage& ids,
                                                                int clusters, const Mask* highlights, int max_samples) {
  if (!color.same_shape(positions) || !color.same_shape(normals) || !color.same_shape(ids)) {
    throw Error("brdf specular: colour, positions, normals and cluster ids must have the same size");
  }
  const auto count = static_cast<std::size_t>(std::max(0, clusters));
  // Two passes instead of lists of every pixel: the first counts each cluster's usable pixels
  // (bright: in the highlight mask; plain: the rest), the second picks the strided ones.
  auto usable = [&](std::size_t i) -> int {  // 0: skip, 1: plain, 2: bright
    const std::uint16_t label = ids.pixels()[i];
    if (label == 0 || label > count) return 0;
    const Rgb8 c = color.pixels()[i];
    if (std::max({c.r, c.g, c.b}) >= 254) return 0;
    if (!is_valid_normal(normals.pixels()[i]) || !is_valid_depth(positions.pixels()[i].z)) return 0;
    return highlights && highlights->pixels()[i] ? 2 : 1;
  };
  struct Stride {
    std::size_t size = 0, take = 0, seen = 0, taken = 0;
    // Picks element t * size / take for t < take (all of them when take >= size).
    [[nodiscard]] bool next() {
      const bool pick = taken < take && (take >= size || seen == taken * size / take);
      ++seen;
      taken += pick ? 1 : 0;
      return pick;
    }
  };
  std::vector<Stride> plain(count), bright(count);
  std::vector<std::uint8_t> kind(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    kind[i] = static_cast<std::uint8_t>(usable(i));
    if (kind[i] == 0) continue;
    ++(kind[i] == 2 ? bright : plain)[ids.pixels()[i] - 1u].size;
  }
  const auto budget = static_cast<std::size_t>(std::max(0, max_samples));
  for (std::size_t k = 0; k < count; ++k) {
    bright[k].take = std::min(bright[k].size, budget / 2);
    plain[k].take = std::min(plain[k].size, budget - bright[k].take);
  }
  std::vector<std::vector<std::uint32_t>> chosen_bright(count), chosen_plain(count);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (kind[i] == 0) continue;
    const std::size_t k = ids.pixels()[i] - 1u;
    if ((kind[i] == 2 ? bright : plain)[k].next()) (kind[i] == 2 ? chosen_bright : chosen_plain)[k].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<std::vector<SpecularSample>> out(count);
  for (std::size_t k = 0; k < count; ++k) {
    out[k].reserve(chosen_bright[k].size() + chosen_plain[k].size());
    for (const auto* list : {&chosen_bright[k], &chosen_plain[k]}) {
      for (const std::uint32_t i : *list) {
        const Rgb8 c = color.pixels()[i];
        const Float3 p = positions.pixels()[i], n = normals.pixels()[i];
        out[k].push_back(
            {{srgb8_to_linear(c.r), srgb8_to_linear(c.g), srgb8_to_linear(c.b)}, {p.x, p.y, p.z}, {n.x, n.y, n.z}});
      }
    }
  }
  return out;
}

std::vector<SpecularSample> select_samples(const ColorImage& color, const PositionMap& positions,
                                           const NormalMap& normals, const LabelImage& ids, int cluster,
                                           const Mask* highlights, int max_samples) {
  if (!color.same_shape(ids)) throw Error("brdf specular: colour, positions, normals and cluster ids must have the same size");
  // Only `cluster` (label cluster + 1) is kept: the others map to label 0.
  LabelImage only(ids.width(), ids.height());
  const auto label = static_cast<std::uint16_t>(cluster + 1);
  for (std::size_t i = 0; i < ids.size(); ++i) only.pixels()[i] = ids.pixels()[i] == label ? 1 : 0;
  return std::move(select_cluster_samples(color, positions, normals, only, 1, highlights, max_samples)[0]);
}

std::unique_ptr<SpecularSolver> make_nelder_mead_solver() { return std::make_unique<NelderMeadSolver>(); }

namespace detail {
void finish_fit(SpecularFit& fit, const SpecularProblem& problem, const SpecularOptions& options) {
  finish(fit, problem, options);
}
}  // namespace detail

}  // namespace relight::brdf
