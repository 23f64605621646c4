// The synthetic colour camera's blur and noise (camera_effects.h): known amounts, reproducible.
#include "relight/synth/camera_effects.h"

#include <gtest/gtest.h>

#include <cmath>

namespace relight::synth {
namespace {

TEST(CameraEffects, BlurSpreadsAStepAsAGaussianOfSigma) {
  RadianceImage step(64, 8);
  for (int r = 0; r < 8; ++r)
    for (int c = 32; c < 64; ++c) step(r, c) = {1.f, 1.f, 1.f};
  const double sigma = 2.0;
  const RadianceImage blurred = blur_radiance(step, sigma);
  // The blurred step is the Gaussian's CDF: Phi((x - 31.5) / sigma) at pixel centres.
  for (int c = 24; c < 40; ++c) {
    const double expected = 0.5 * std::erfc(-(c - 31.5) / (sigma * std::sqrt(2.0)));
    EXPECT_NEAR(blurred(4, c).x, expected, 4e-3) << c;  // sampled weights against the continuous CDF
  }
  EXPECT_EQ(blur_radiance(step, 0.0)(4, 31).x, 0.f);
}

TEST(CameraEffects, NoiseHasTheModelsSigmaAndIsNewEveryFrameButReproducible) {
  const ColorCameraEffects effects{0.0, 1.0, 0.05};
  const ColorImage grey(200, 200, Rgb8{100, 100, 100});
  const ColorImage a = add_color_noise(grey, effects, 7, 0), b = add_color_noise(grey, effects, 7, 1);
  const ColorImage again = add_color_noise(grey, effects, 7, 0, 1);  // one thread: the same bytes
  double sum = 0, squares = 0;
  int differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double v = a.pixels()[i].g;
    sum += v;
    squares += v * v;
    differ += a.pixels()[i].g != b.pixels()[i].g;
    ASSERT_EQ(a.pixels()[i], again.pixels()[i]);
  }
  const double n = double(a.size()), mean = sum / n, sd = std::sqrt(squares / n - mean * mean);
  EXPECT_NEAR(mean, 100.0, 0.1);
  // sigma(100) = sqrt(1 + 5) plus the rounding's 1/12 variance.
  EXPECT_NEAR(sd, std::sqrt(6.0 + 1.0 / 12.0), 0.05 * std::sqrt(6.0));
  EXPECT_GT(differ, int(n / 2));
  EXPECT_EQ(add_color_noise(grey, {}, 7, 0), grey);
}

}  // namespace
}  // namespace relight::synth
