// The sample-based mapping: hue matching (eqs. 4.20-4.22), the three polynomial models recover
// known transforms exactly, pair finding, the colour error on the synthetic camera (the issue's
// table: methods x models x channel swap, orange and green virtual spheres), and temporal
// smoothing (eq. 4.27) against coefficient jitter under camera noise.
#include "relight/colormap/sample_mapping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "colormap_test_scene.h"
#include "relight/core/error.h"

namespace relight::colormap {
namespace {

TEST(SampleMapping, HueIsTheHsvHue) {
  EXPECT_DOUBLE_EQ(hue({1, 0, 0}), 0.0);
  EXPECT_DOUBLE_EQ(hue({0, 1, 0}), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(hue({0, 0, 1}), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(hue({1, 0, 1}), 5.0 / 6.0);
  EXPECT_DOUBLE_EQ(hue({0.4, 0.4, 0.4}), 0.0);
}

TEST(SampleMapping, HueMatchPrefersSameHueThenNearColour) {
  const Eigen::Vector3d orange{0.8, 0.4, 0.1};
  EXPECT_DOUBLE_EQ(hue_match(orange, orange), 0.5);                     // h_m = 0.5, distance 0
  EXPECT_NEAR(hue_match({1, 0, 0}, {0, 1, 1}), 0.0, 1e-12);            // opposite hues
  EXPECT_GT(hue_match(orange, 0.5 * orange), hue_match(orange, 0.1 * orange));  // same hue: nearer wins
  EXPECT_NEAR(hue_match({0.9, 0.1, 0.1}, {0.1, 0.1, 0.9}), (0.5 - 1.0 / 3.0) / (1.0 + 0.8 * std::sqrt(2.0)), 1e-12);
  EXPECT_GT(hue_match(orange, {0.7, 0.35, 0.1}), hue_match(orange, {0.1, 0.4, 0.8}));
}

ColorMatrix random_pairs_fit(PolynomialModel model, const ColorMatrix& truth) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<ColorPair> pairs;
  for (int i = 0; i < 64; ++i) {
    const Eigen::Vector3d c{unit(random), unit(random), unit(random)};
    pairs.push_back({c, apply(truth, c)});
  }
  return fit_color_mapping(pairs, model);
}

TEST(SampleMapping, EachModelRecoversATransformOfItsOwnForm) {
  ColorMatrix affine;
  affine << 1.2, 0.1, -0.05, 0.02,  //
      0.05, 0.9, 0.08, -0.01,       //
      -0.02, 0.12, 0.7, 0.03;
  EXPECT_LT((random_pairs_fit(PolynomialModel::Affine3x4, affine) - affine).cwiseAbs().maxCoeff(), 1e-3);

  ColorMatrix linear = affine;
  linear.col(3).setZero();
  EXPECT_LT((random_pairs_fit(PolynomialModel::Linear3x3, linear) - linear).cwiseAbs().maxCoeff(), 1e-3);

  ColorMatrix per_channel = ColorMatrix::Zero();
  per_channel.diagonal() << 1.3, 0.95, 0.6;
  per_channel.col(3) << 0.02, -0.01, 0.05;
  EXPECT_LT((random_pairs_fit(PolynomialModel::PerChannelAffine, per_channel) - per_channel).cwiseAbs().maxCoeff(),
            1e-3);
  // A per-channel model cannot express crosstalk: its fit of `affine` has a zero off-diagonal.
  const ColorMatrix restricted = random_pairs_fit(PolynomialModel::PerChannelAffine, affine);
  EXPECT_EQ(restricted(0, 1), 0.0);
  EXPECT_EQ(restricted(2, 0), 0.0);
}

TEST(SampleMapping, DegeneratePairsStayFiniteAndNoPairsGiveIdentity) {
  const std::vector<ColorPair> one_colour(10, ColorPair{{0.5, 0.3, 0.1}, {0.6, 0.3, 0.05}});
  const ColorMatrix fit = fit_color_mapping(one_colour, PolynomialModel::Affine3x4);
  EXPECT_TRUE(fit.allFinite());
  EXPECT_LT((apply(fit, {0.5, 0.3, 0.1}) - Eigen::Vector3d(0.6, 0.3, 0.05)).norm(), 1e-3);
  EXPECT_EQ(fit_color_mapping({}, PolynomialModel::Linear3x3), identity_color_matrix());
}

TEST(SampleMapping, FindsOnePairPerSampleAndSixWithChannelSwap) {
  const auto& triple = test::orange_triple();
  SampleMappingOptions options;
  const auto pairs = find_color_pairs(triple.real, triple.real_virtual, triple.camera, options);
  ASSERT_EQ(pairs.size(), 64u);
  // Matched real colours share the orange sphere's hue family (red > green > blue) for all but
  // a few samples (the sphere's rim and highlight are less saturated).
  const auto orange = std::count_if(pairs.begin(), pairs.end(), [](const ColorPair& pair) {
    return pair.rendered[0] > pair.rendered[1] && pair.rendered[1] > pair.rendered[2];
  });
  EXPECT_GE(orange, 56);
  options.channel_swap = true;
  EXPECT_EQ(find_color_pairs(triple.real, triple.real_virtual, triple.camera, options).size(), 6u * 64u);
  EXPECT_TRUE(find_color_pairs(triple.real, triple.real, triple.camera, options).empty());  // no virtual pixel
  EXPECT_THROW((void)find_color_pairs(triple.real, triple.real_virtual, ColorImage(3, 3), options), Error);
}

double sample_delta_e(const truth::SyntheticTriple& triple, PolynomialModel model, bool swap) {
  SampleMappingOptions options;
  options.model = model;
  options.channel_swap = swap;
  SampleColorMapper mapper(options);
  RadianceImage delta;
  (void)mapper.map(triple.real, triple.real_virtual, triple.camera, delta);
  return test::virtual_delta_e(triple, delta);
}

// The table. Measured (mean CIEDE2000 over the sphere, before 7.25 orange / 8.06 green):
// without channel swap every model is <= 2.6; with it every model is worse (5-8.5), because the
// swapped pairs claim the camera treats R, G and B alike while its white balance does not.
TEST(SampleMapping, ReducesTheColourErrorOfTheVirtualObject) {
  for (const bool green : {false, true}) {
    const auto& triple = green ? test::green_triple() : test::orange_triple();
    RadianceImage identity;
    sample_delta(triple.real, triple.real_virtual, identity_color_matrix(), {}, identity);
    const double before = test::virtual_delta_e(triple, identity);
    std::printf("[ colormap ] %s sphere: before %.2f\n", green ? "green" : "orange", before);
    EXPECT_GT(before, 6.0);
    for (const auto model : {PolynomialModel::PerChannelAffine, PolynomialModel::Linear3x3, PolynomialModel::Affine3x4}) {
      const double after = sample_delta_e(triple, model, false);
      const double after_swap = sample_delta_e(triple, model, true);
      std::printf("[ colormap ] %s sphere, %s: after %.2f, with channel swap %.2f\n", green ? "green" : "orange",
                  to_string(model), after, after_swap);
      EXPECT_LE(after, 3.0) << to_string(model);
      EXPECT_GT(after_swap, after) << to_string(model);
      if (model != PolynomialModel::PerChannelAffine) {
        EXPECT_LE(after, 1.5) << to_string(model) << ": crosstalk is linear, these models can express it";
      }
    }
  }
}

// Coefficient jitter: mean Frobenius norm of A_t - A_{t-1} over frames with independent camera noise.
double coefficient_jitter(double u) {
  SampleMappingOptions options;
  options.smoothing = u;
  SampleColorMapper mapper(options);
  truth::SyntheticTripleOptions triple_options;
  const auto& clean = test::orange_triple();
  RadianceImage delta;
  double sum = 0.0;
  int counted = 0;
  ColorMatrix previous;
  constexpr int kFrames = 24, kWarmUp = 4;
  for (int frame = 0; frame < kFrames; ++frame) {
    truth::CameraColorTransform camera = triple_options.camera;
    camera.noise_sigma = 3.0;
    camera.noise_seed = 1000 + static_cast<std::uint64_t>(frame);
    const ColorImage noisy = truth::apply_camera(clean.real, camera);
    const ColorMatrix current = mapper.map(clean.real, clean.real_virtual, noisy, delta);
    if (frame > kWarmUp) {
      sum += (current - previous).norm();
      ++counted;
    }
    previous = current;
  }
  return sum / counted;
}

TEST(SampleMapping, SmoothingCutsCoefficientJitterAtLeastThreefold) {
  const double smoothed = coefficient_jitter(0.3);
  const double raw = coefficient_jitter(1.0);
  std::printf("[ colormap ] coefficient jitter: u=0.3 %.5f, u=1 %.5f, ratio %.2f\n", smoothed, raw, raw / smoothed);
  EXPECT_GT(raw, 0.0);
  EXPECT_GE(raw / smoothed, 3.0);
}

}  // namespace
}  // namespace relight::colormap
