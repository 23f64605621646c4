// Vectorised forms of the specular objective (specular_terms.h).
#include "specular_terms.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <numbers>

#include "relight/core/phong.h"

namespace relight::brdf::detail {

namespace {

constexpr double kInvPi = std::numbers::inv_pi;
// <omega_o . r_l> at or below this counts as no lobe (core/phong.h, as in model_radiance).
constexpr double kMinRv = kPhongMinLobeCosine;
// exp(n g) below exp(-46) ~ 1e-20: a sample whose every lobe is that small for the current n
// contributes its observation alone (the lobes change F by less than double rounding).
constexpr double kNegligibleExponent = -46.0;

Eigen::ArrayXf coordinate(const std::vector<SpecularSample>& samples, int axis, Eigen::Vector3f SpecularSample::*field) {
  Eigen::ArrayXf out(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i) out[static_cast<Eigen::Index>(i)] = (samples[i].*field)[axis];
  return out;
}

}  // namespace

ShapeTerms::ShapeTerms(const SpecularProblem& problem, const ShadingLights& lights) {
  const auto count = static_cast<Eigen::Index>(problem.samples.size());
  for (int c = 0; c < 3; ++c) base_[static_cast<std::size_t>(c)].resize(count);
  lobes_.resize(lights.lights.size());
  for (Lobe& lobe : lobes_) {
    for (Eigen::ArrayXd& e : lobe.irradiance) e.setZero(count);
    lobe.log_rv.setZero(count);
  }
  for (Eigen::Index i = 0; i < count; ++i) {
    const SpecularSample& s = problem.samples[static_cast<std::size_t>(i)];
    const Eigen::Vector3d p = s.position.cast<double>(), n = s.normal.cast<double>();
    const Eigen::Vector3d view = -p.normalized();
    Eigen::Vector3d diffuse = lights.ambient.cast<double>();
    for (std::size_t l = 0; l < lights.lights.size(); ++l) {
      const ShadingLight& light = lights.lights[l];
      Eigen::Vector3d dir = light.vector.cast<double>();
      double scale = 1.0;
      if (light.point) {
        dir -= p;
        scale = 1.0 / dir.squaredNorm();
      }
      dir.normalize();
      const double cosine = n.dot(dir);
      if (!(cosine > 0.0)) continue;
      const Eigen::Vector3d e = light.power.cast<double>() * (scale * cosine);
      diffuse += e * kInvPi;
      const double rv = (2.0 * cosine * n - dir).dot(view);
      if (!(rv > kMinRv)) continue;
      for (int c = 0; c < 3; ++c) lobes_[l].irradiance[static_cast<std::size_t>(c)][i] = e[c];
      lobes_[l].log_rv[i] = std::log(rv);
    }
    for (int c = 0; c < 3; ++c) {
      base_[static_cast<std::size_t>(c)][i] = double(s.radiance[c]) - double(problem.kd[c]) * diffuse[c];
    }
  }
  sort_by_lobe();
}

void ShapeTerms::sort_by_lobe() {
  const Eigen::Index count = samples();
  std::vector<double> widest(static_cast<std::size_t>(count), -std::numeric_limits<double>::infinity());
  for (const Lobe& lobe : lobes_) {
    for (Eigen::Index i = 0; i < count; ++i) {
      if (lobe.irradiance[0][i] != 0.0 || lobe.irradiance[1][i] != 0.0 || lobe.irradiance[2][i] != 0.0) {
        widest[static_cast<std::size_t>(i)] = std::max(widest[static_cast<std::size_t>(i)], lobe.log_rv[i]);
      }
    }
  }
  std::vector<Eigen::Index> order(static_cast<std::size_t>(count));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return widest[static_cast<std::size_t>(a)] > widest[static_cast<std::size_t>(b)];
  });
  auto permute = [&](Eigen::ArrayXd& a) {
    Eigen::ArrayXd sorted(count);
    for (Eigen::Index i = 0; i < count; ++i) sorted[i] = a[order[static_cast<std::size_t>(i)]];
    a.swap(sorted);
  };
  for (Eigen::ArrayXd& b : base_) permute(b);
  for (Lobe& lobe : lobes_) {
    for (Eigen::ArrayXd& e : lobe.irradiance) permute(e);
    permute(lobe.log_rv);
  }
  widest_.resize(static_cast<std::size_t>(count));
  for (Eigen::Index i = 0; i < count; ++i) widest_[static_cast<std::size_t>(i)] = widest[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
  tail_bb_.assign(static_cast<std::size_t>(count) + 1, 0.0);
  for (Eigen::Index i = count - 1; i >= 0; --i) {
    double bb = 0.0;
    for (const Eigen::ArrayXd& b : base_) bb += b[i] * b[i];
    tail_bb_[static_cast<std::size_t>(i)] = tail_bb_[static_cast<std::size_t>(i) + 1] + bb;
  }
}

Eigen::Index ShapeTerms::lit_samples(double n) const {
  const double threshold = kNegligibleExponent / n;
  return static_cast<Eigen::Index>(std::partition_point(widest_.begin(), widest_.end(),
                                                        [&](double g) { return g >= threshold; }) -
                                   widest_.begin());
}

void ShapeTerms::lobe_sums(double n, Eigen::Index lit, std::array<Eigen::ArrayXd, 3>& sums,
                           std::array<Eigen::ArrayXd, 3>* slope) const {
  for (Eigen::ArrayXd& s : sums) s.setZero(lit);
  if (slope) {
    for (Eigen::ArrayXd& s : *slope) s.setZero(lit);
  }
  Eigen::ArrayXd lobe;
  for (const Lobe& l : lobes_) {
    lobe = (n * l.log_rv.head(lit)).exp();
    for (std::size_t c = 0; c < 3; ++c) {
      sums[c] += l.irradiance[c].head(lit) * lobe;
      if (slope) (*slope)[c] += l.irradiance[c].head(lit) * l.log_rv.head(lit) * lobe;
    }
  }
}

double ShapeTerms::objective(double ks, double n) const {
  const Eigen::Index lit = lit_samples(n);
  std::array<Eigen::ArrayXd, 3> sums;
  lobe_sums(n, lit, sums, nullptr);
  const double scale = ks * phong_lobe_normalisation(n);
  double f = tail_bb_[static_cast<std::size_t>(lit)];
  for (std::size_t c = 0; c < 3; ++c) f += (base_[c].head(lit) - scale * sums[c]).square().sum();
  return f;
}

ShapeTerms::Projected ShapeTerms::best_ks(double n, double ks_max) const {
  const Eigen::Index lit = lit_samples(n);
  std::array<Eigen::ArrayXd, 3> sums;
  lobe_sums(n, lit, sums, nullptr);
  const double lobe_scale = phong_lobe_normalisation(n);
  const double bb = tail_bb_[0];
  double bt = 0.0, tt = 0.0;
  for (std::size_t c = 0; c < 3; ++c) {
    bt += lobe_scale * (base_[c].head(lit) * sums[c]).sum();
    tt += lobe_scale * lobe_scale * sums[c].square().sum();
  }
  const double ks = tt > 0.0 ? std::clamp(bt / tt, 0.0, ks_max) : 0.0;
  return {ks, std::max(0.0, bb - 2.0 * ks * bt + ks * ks * tt)};
}

void ShapeTerms::residuals(double ks, double n, double* residuals, double* jacobian) const {
  const Eigen::Index lit = lit_samples(n), count = samples();
  std::array<Eigen::ArrayXd, 3> sums, slope;
  lobe_sums(n, lit, sums, jacobian ? &slope : nullptr);
  const double lobe_scale = phong_lobe_normalisation(n);
  for (std::size_t c = 0; c < 3; ++c) {
    Eigen::Map<Eigen::ArrayXd, 0, Eigen::InnerStride<3>> r(residuals + c, count);
    r.head(lit) = base_[c].head(lit) - ks * lobe_scale * sums[c];
    r.tail(count - lit) = base_[c].tail(count - lit);
    if (!jacobian) continue;
    Eigen::Map<Eigen::ArrayXd, 0, Eigen::InnerStride<6>> d_ks(jacobian + 2 * c, count);
    Eigen::Map<Eigen::ArrayXd, 0, Eigen::InnerStride<6>> d_n(jacobian + 2 * c + 1, count);
    d_ks.head(lit) = -lobe_scale * sums[c];
    d_n.head(lit) = -ks * (0.5 * kInvPi * sums[c] + lobe_scale * slope[c]);
    d_ks.tail(count - lit).setZero();
    d_n.tail(count - lit).setZero();
  }
}

ShadingLights moved_lights(const ShadingLights& ordered, int moving, const double* offsets) {
  ShadingLights moved = ordered;
  for (int l = 0; l < moving && offsets; ++l) {
    for (int c = 0; c < 3; ++c) {
      moved.lights[static_cast<std::size_t>(l)].vector[c] += static_cast<float>(offsets[3 * l + c]);
    }
  }
  return moved;
}

namespace {

double log_n_spacing(const SpecularOptions& options, int count) {
  const double low = std::log(static_cast<double>(options.n_min)), high = std::log(static_cast<double>(options.n_max));
  return (high - low) / (std::max(2, count) - 1);
}

}  // namespace

std::vector<double> log_spaced_exponents(const SpecularOptions& options, int count) {
  const double low = std::log(static_cast<double>(options.n_min)), spacing = log_n_spacing(options, count);
  std::vector<double> exponents(static_cast<std::size_t>(std::max(2, count)));
  for (std::size_t k = 0; k < exponents.size(); ++k) exponents[k] = std::exp(low + static_cast<double>(k) * spacing);
  return exponents;
}

StartShape start_shape_spacing(const SpecularOptions& options) {
  StartShape start;
  start.log_n_spacing = log_n_spacing(options, options.start_exponents);
  return start;
}

StartShape start_shape(const ShapeTerms& terms, const SpecularOptions& options) {
  StartShape best = start_shape_spacing(options);
  if (options.start) {
    best.ks = std::clamp(static_cast<double>(options.start->ks), 0.0, static_cast<double>(options.ks_max));
    best.n = std::clamp(static_cast<double>(options.start->n), static_cast<double>(options.n_min),
                        static_cast<double>(options.n_max));
    return best;
  }
  double best_f = std::numeric_limits<double>::infinity();
  const std::vector<double> exponents = log_spaced_exponents(options, options.start_exponents);
  for (const double n : exponents) {
    const ShapeTerms::Projected p = terms.best_ks(n, options.ks_max);
    if (p.objective < best_f) {
      best_f = p.objective;
      best.ks = p.ks;
      best.n = n;
    }
  }
  best.evaluations = static_cast<int>(exponents.size());
  return best;
}

FullModel::FullModel(const SpecularProblem& problem, const ShadingLights& ordered, int moving)
    : kd_(problem.kd), ambient_(ordered.ambient), lights_(ordered), moving_(moving) {
  const auto& s = problem.samples;
  px_ = coordinate(s, 0, &SpecularSample::position);
  py_ = coordinate(s, 1, &SpecularSample::position);
  pz_ = coordinate(s, 2, &SpecularSample::position);
  nx_ = coordinate(s, 0, &SpecularSample::normal);
  ny_ = coordinate(s, 1, &SpecularSample::normal);
  nz_ = coordinate(s, 2, &SpecularSample::normal);
  for (int c = 0; c < 3; ++c) radiance_[static_cast<std::size_t>(c)] = coordinate(s, c, &SpecularSample::radiance);
  const Eigen::ArrayXf inv_distance = (px_.square() + py_.square() + pz_.square()).rsqrt();
  vx_ = -px_ * inv_distance;
  vy_ = -py_ * inv_distance;
  vz_ = -pz_ * inv_distance;
  n_dot_v_ = nx_ * vx_ + ny_ * vy_ + nz_ * vz_;
}

double FullModel::objective(double ks_in, double n_in, const double* offsets) {
  const auto ks = static_cast<float>(ks_in), n = static_cast<float>(n_in);
  constexpr float kInvPiF = std::numbers::inv_pi_v<float>;
  constexpr auto kMinRvF = static_cast<float>(kMinRv);
  const float lobe_scale = ks * phong_lobe_normalisation(n);
  const Eigen::Index count = px_.size();
  for (int c = 0; c < 3; ++c) model_[static_cast<std::size_t>(c)].setConstant(count, kd_[c] * ambient_[c]);
  for (std::size_t l = 0; l < lights_.lights.size(); ++l) {
    const ShadingLight& light = lights_.lights[l];
    Eigen::Vector3f at = light.vector;
    if (static_cast<int>(l) < moving_) {
      at += Eigen::Vector3d(offsets[3 * l], offsets[3 * l + 1], offsets[3 * l + 2]).cast<float>();
    }
    if (light.point) {
      dx_ = at.x() - px_;
      dy_ = at.y() - py_;
      dz_ = at.z() - pz_;
      inv_d_ = (dx_.square() + dy_.square() + dz_.square()).rsqrt();
      dx_ *= inv_d_;
      dy_ *= inv_d_;
      dz_ *= inv_d_;
      irradiance_ = inv_d_.square();  // 1 / d^2
    } else {
      at.normalize();
      dx_.setConstant(count, at.x());
      dy_.setConstant(count, at.y());
      dz_.setConstant(count, at.z());
      irradiance_.setOnes(count);
    }
    cosine_ = nx_ * dx_ + ny_ * dy_ + nz_ * dz_;
    rv_ = 2.f * cosine_ * n_dot_v_ - (vx_ * dx_ + vy_ * dy_ + vz_ * dz_);
    irradiance_ = (cosine_ > 0.f).select(irradiance_ * cosine_, 0.f);
    lobe_ = (rv_ > kMinRvF).select((n * rv_.max(kMinRvF).log()).exp(), 0.f);
    for (int c = 0; c < 3; ++c) {
      model_[static_cast<std::size_t>(c)] += (light.power[c] * irradiance_) * (kd_[c] * kInvPiF + lobe_scale * lobe_);
    }
  }
  double f = 0.0;
  for (std::size_t c = 0; c < 3; ++c) f += (radiance_[c] - model_[c]).cast<double>().square().sum();
  return f;
}

}  // namespace relight::brdf::detail
