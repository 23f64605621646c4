// Sample-based colour mapping (definition in sample_mapping.h).
#include "relight/colormap/sample_mapping.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "relight/colormap/color_space.h"
#include "relight/colormap/statistics_transfer.h"
#include "relight/core/error.h"

namespace relight::colormap {

namespace {

constexpr double kRidge = 1e-4;

Eigen::Vector3d to_vector(const Float3& c) { return {c.x, c.y, c.z}; }

// A real pixel the matcher may pick, with its hue precomputed once per frame.
struct Candidate {
  Eigen::Vector3d rendered;
  double hue = 0.0;
  std::size_t index = 0;
};

std::vector<Candidate> grid_candidates(const RadianceImage& real, const RadianceImage& real_virtual,
                                       const ColorImage& camera, const SampleMappingOptions& options) {
  std::vector<Candidate> candidates;
  const int step = std::max(1, options.grid_step);
  for (int row = step / 2; row < real.height(); row += step) {
    for (int col = step / 2; col < real.width(); col += step) {
      if (!is_statistics_pixel(real(row, col), real_virtual(row, col), camera(row, col), options.tone_map)) continue;
      const Eigen::Vector3d rendered = to_vector(tone_map(real(row, col), options.tone_map));
      candidates.push_back({rendered, hue(rendered),
                            static_cast<std::size_t>(row) * static_cast<std::size_t>(real.width()) +
                                static_cast<std::size_t>(col)});
    }
  }
  return candidates;
}

std::vector<std::size_t> virtual_samples(const RadianceImage& real, const RadianceImage& real_virtual, int samples) {
  std::vector<std::size_t> virtual_pixels;
  for (std::size_t i = 0; i < real.size(); ++i) {
    if (!(real.pixels()[i] == real_virtual.pixels()[i])) virtual_pixels.push_back(i);
  }
  std::vector<std::size_t> chosen;
  const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(std::max(samples, 0)), virtual_pixels.size());
  for (std::size_t s = 0; s < n; ++s) chosen.push_back(virtual_pixels[(2 * s + 1) * virtual_pixels.size() / (2 * n)]);
  return chosen;
}

double hue_match_precomputed(double hue_a, const Eigen::Vector3d& a, double hue_b, const Eigen::Vector3d& b) {
  const double dh = std::fabs(hue_a - hue_b);
  const double hm = 0.5 - std::min(dh, 1.0 - dh);
  return hm / (1.0 + (a - b).norm());
}

// Features of one model for one output channel k: the row of the design matrix.
Eigen::VectorXd features(const Eigen::Vector3d& c, PolynomialModel model, int k) {
  switch (model) {
    case PolynomialModel::PerChannelAffine: return Eigen::Vector2d(1.0, c[k]);
    case PolynomialModel::Linear3x3: return c;
    case PolynomialModel::Affine3x4: return Eigen::Vector4d(c[0], c[1], c[2], 1.0);
  }
  return {};
}

// The identity mapping's coefficients in the same layout (the ridge pulls towards them).
Eigen::VectorXd identity_coefficients(PolynomialModel model, int k) {
  switch (model) {
    case PolynomialModel::PerChannelAffine: return Eigen::Vector2d(0.0, 1.0);
    case PolynomialModel::Linear3x3: return Eigen::Vector3d::Unit(k);
    case PolynomialModel::Affine3x4: {
      Eigen::Vector4d w = Eigen::Vector4d::Zero();
      w[k] = 1.0;
      return w;
    }
  }
  return {};
}

void store_row(ColorMatrix& a, const Eigen::VectorXd& w, PolynomialModel model, int k) {
  a.row(k).setZero();
  switch (model) {
    case PolynomialModel::PerChannelAffine:
      a(k, 3) = w[0];
      a(k, k) = w[1];
      break;
    case PolynomialModel::Linear3x3: a.row(k).head<3>() = w.transpose(); break;
    case PolynomialModel::Affine3x4: a.row(k) = w.transpose(); break;
  }
}

}  // namespace

ColorMatrix identity_color_matrix() {
  ColorMatrix a = ColorMatrix::Zero();
  a.leftCols<3>().setIdentity();
  return a;
}

double hue(const Eigen::Vector3d& rgb) {
  const double max = rgb.maxCoeff(), min = rgb.minCoeff();
  const double chroma = max - min;
  if (chroma <= 0.0) return 0.0;
  double h = 0.0;
  if (max == rgb[0]) {
    h = std::fmod((rgb[1] - rgb[2]) / chroma, 6.0);
  } else if (max == rgb[1]) {
    h = (rgb[2] - rgb[0]) / chroma + 2.0;
  } else {
    h = (rgb[0] - rgb[1]) / chroma + 4.0;
  }
  h /= 6.0;
  return h < 0.0 ? h + 1.0 : h;
}

double hue_match(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return hue_match_precomputed(hue(a), a, hue(b), b); }

std::vector<ColorPair> find_color_pairs(const RadianceImage& real, const RadianceImage& real_virtual,
                                        const ColorImage& camera, const SampleMappingOptions& options) {
  if (!real.same_shape(real_virtual) || !real.same_shape(camera)) {
    throw Error("colormap: L_r, L_rv and the camera image must have the same size");
  }
  const std::vector<Candidate> candidates = grid_candidates(real, real_virtual, camera, options);
  std::vector<ColorPair> pairs;
  if (candidates.empty()) return pairs;
  for (const std::size_t sample : virtual_samples(real, real_virtual, options.samples)) {
    const Eigen::Vector3d colour = to_vector(tone_map(real_virtual.pixels()[sample], options.tone_map));
    const double colour_hue = hue(colour);
    const Candidate* best = &candidates.front();
    double best_match = -1.0;
    for (const Candidate& candidate : candidates) {
      const double match = hue_match_precomputed(colour_hue, colour, candidate.hue, candidate.rendered);
      if (match > best_match) {
        best_match = match;
        best = &candidate;
      }
    }
    pairs.push_back({best->rendered, to_vector(decode_srgb8(camera.pixels()[best->index]))});
  }
  if (options.channel_swap) {
    static constexpr std::array<std::array<int, 3>, 5> kPermutations = {
        {{1, 0, 2}, {0, 2, 1}, {2, 1, 0}, {1, 2, 0}, {2, 0, 1}}};
    const std::size_t originals = pairs.size();
    for (std::size_t i = 0; i < originals; ++i) {
      for (const auto& p : kPermutations) {
        const ColorPair& pair = pairs[i];
        pairs.push_back({{pair.rendered[p[0]], pair.rendered[p[1]], pair.rendered[p[2]]},
                         {pair.camera[p[0]], pair.camera[p[1]], pair.camera[p[2]]}});
      }
    }
  }
  return pairs;
}

ColorMatrix fit_color_mapping(const std::vector<ColorPair>& pairs, PolynomialModel model) {
  ColorMatrix a = identity_color_matrix();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Index n = features(Eigen::Vector3d::Zero(), model, k).size();
    // Normal equations with the ridge: (F^T F + l I) w = F^T y + l w_identity.
    Eigen::MatrixXd normal = kRidge * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd rhs = kRidge * identity_coefficients(model, k);
    for (const ColorPair& pair : pairs) {
      const Eigen::VectorXd f = features(pair.rendered, model, k);
      normal.noalias() += f * f.transpose();
      rhs.noalias() += f * pair.camera[k];
    }
    store_row(a, normal.ldlt().solve(rhs), model, k);
  }
  return a;
}

void sample_delta(const RadianceImage& real, const RadianceImage& real_virtual, const ColorMatrix& mapping,
                  const ToneMap& tm, RadianceImage& delta) {
  if (!real.same_shape(real_virtual)) throw Error("colormap: L_r and L_rv must have the same size");
  delta.resize(real.width(), real.height());
  for (std::size_t i = 0; i < real.size(); ++i) {
    const Float3& r = real.pixels()[i];
    const Float3& rv = real_virtual.pixels()[i];
    if (r == rv) {
      delta.pixels()[i] = Float3{};
      continue;
    }
    // tau_sb is affine, so tau(a) - tau(b) = M (a - b): the offset cancels.
    const Eigen::Vector3d d = mapping.leftCols<3>() * (to_vector(tone_map(rv, tm)) - to_vector(tone_map(r, tm)));
    delta.pixels()[i] = {static_cast<float>(d[0]), static_cast<float>(d[1]), static_cast<float>(d[2])};
  }
}

const ColorMatrix& SampleColorMapper::map(const RadianceImage& real, const RadianceImage& real_virtual,
                                          const ColorImage& camera, RadianceImage& delta) {
  const std::vector<ColorPair> pairs = find_color_pairs(real, real_virtual, camera, options_);
  if (!pairs.empty()) {
    const ColorMatrix fitted = fit_color_mapping(pairs, options_.model);
    const double u = fitted_ ? options_.smoothing : 1.0;  // the first fit has nothing to blend with
    coefficients_ = u * fitted + (1.0 - u) * coefficients_;
    fitted_ = true;
  }
  sample_delta(real, real_virtual, coefficients_, options_.tone_map, delta);
  return coefficients_;
}

}  // namespace relight::colormap
