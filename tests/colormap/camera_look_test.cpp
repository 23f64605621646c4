// The camera's look on synthetic images with known blur and noise: the estimators recover them
// (camera_blur.h, camera_noise.h) and the composite puts them on the virtual layer
// (camera_look.h).
#include "relight/colormap/camera_look.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "relight/colormap/color_space.h"
#include "relight/core/error.h"
#include "relight/synth/camera_effects.h"

namespace relight::colormap {
namespace {

constexpr int kWidth = 320, kHeight = 240;

/// A linear radiance pattern of rectangles and discs of several levels over a mid-grey ground,
/// box-filtered over 4x4 sub-pixels (edges at any sub-pixel position, as a camera's would be).
RadianceImage shapes(std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  struct Shape {
    bool disc;
    double x, y, a, b;
    float level;
  };
  std::vector<Shape> list;
  list.reserve(40);
  for (int i = 0; i < 40; ++i)
    list.push_back({unit(random) < 0.5, unit(random) * kWidth, unit(random) * kHeight, 8 + 30 * unit(random),
                    8 + 30 * unit(random), float(0.03 + 0.6 * unit(random))});
  RadianceImage out(kWidth, kHeight);
  constexpr int kSub = 4;
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < kWidth; ++c) {
      float sum = 0.f;
      for (int i = 0; i < kSub; ++i) {
        for (int j = 0; j < kSub; ++j) {
          const double x = c + (j + 0.5) / kSub, y = r + (i + 0.5) / kSub;
          float level = 0.18f;
          for (const Shape& s : list) {
            const double dx = x - s.x, dy = y - s.y;
            const bool inside = s.disc ? dx * dx + dy * dy < s.a * s.a : std::abs(dx) < s.a && std::abs(dy) < s.b;
            if (inside) level = s.level;
          }
          sum += level;
        }
      }
      const float v = sum / (kSub * kSub);
      out(r, c) = {v, 0.9f * v, 0.8f * v};
    }
  }
  return out;
}

/// A Gaussian of sigma (pixels), then a box of `motion` pixels along x.
RadianceImage blurred(const RadianceImage& image, double sigma, double motion = 0.0) {
  RadianceImage out = synth::blur_radiance(image, sigma);
  if (motion <= 0.0) return out;
  const RadianceImage source = out;
  const int samples = 4 * static_cast<int>(std::ceil(motion));
  for (int r = 0; r < out.height(); ++r)
    for (int c = 0; c < out.width(); ++c) {
      Float3 sum;
      for (int k = 0; k < samples; ++k) {
        const double x = c + ((k + 0.5) / samples - 0.5) * motion;
        const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, out.width() - 1);
        const int x1 = std::min(x0 + 1, out.width() - 1);
        const float f = float(x - std::floor(x));
        sum += (1.f / samples) * ((1.f - f) * source(r, x0) + f * source(r, x1));
      }
      out(r, c) = sum;
    }
  return out;
}

ColorImage encoded(const RadianceImage& image) {
  ColorImage out(image.width(), image.height());
  for (std::size_t i = 0; i < out.size(); ++i) out.pixels()[i] = encode_srgb8(image.pixels()[i]);
  return out;
}

/// The camera's noise model of the tests: sigma(I) = sqrt(0.5 + 0.04 I) code values per channel.
double true_noise(double code) { return std::sqrt(0.5 + 0.04 * code); }

ColorImage with_noise(const RadianceImage& image, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  ColorImage out(image.width(), image.height());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Float3& p = image.pixels()[i];
    std::uint8_t channels[3];
    const float values[3] = {p.x, p.y, p.z};
    for (int ch = 0; ch < 3; ++ch) {
      const double code = 255.0 * linear_to_srgb(std::clamp(values[ch], 0.f, 1.f));
      channels[ch] =
          static_cast<std::uint8_t>(std::clamp(std::lround(code + true_noise(code) * gauss(random)), 0L, 255L));
    }
    out.pixels()[i] = {channels[0], channels[1], channels[2]};
  }
  return out;
}

TEST(CameraBlur, EstimatesAKnownGaussianWithin20Percent) {
  const RadianceImage sharp = shapes(1);
  for (const double sigma : {1.0, 1.6, 2.5}) {
    const BlurEstimate e = estimate_camera_blur(encoded(blurred(sharp, sigma)));
    ASSERT_TRUE(e.valid());
    EXPECT_GT(e.edges, 200);
    // The 4x4 box of the pattern's pixels adds its variance 1/12 to the blur's.
    const double truth = std::sqrt(sigma * sigma + 1.0 / 12.0);
    EXPECT_NEAR(e.sigma_px, truth, 0.2 * truth) << "sigma " << sigma << ", " << e.edges << " edges";
  }
}

TEST(CameraBlur, EdgesAlongTheMotionMeasureTheDefocusAlone) {
  const double sigma = 1.2;
  const ColorImage image = encoded(blurred(shapes(2), sigma, 9.0));
  const double truth = std::sqrt(sigma * sigma + 1.0 / 12.0);
  const BlurEstimate all = estimate_camera_blur(image);
  const BlurEstimate along = estimate_camera_blur(image, {}, Eigen::Vector2f(9.f, 0.f));
  ASSERT_TRUE(along.valid());
  EXPECT_NEAR(along.sigma_px, truth, 0.2 * truth);
  EXPECT_GT(all.sigma_px, 1.2 * along.sigma_px) << "the motion-blurred edges widen the isotropic estimate";
}

TEST(CameraBlur, AFlatImageHasNoEstimate) {
  const BlurEstimate e = estimate_camera_blur(ColorImage(64, 48, Rgb8{90, 90, 90}));
  EXPECT_FALSE(e.valid());
  EXPECT_EQ(e.sigma_px, 0.0);
}

/// A smooth ramp across the image (every intensity band) with a few shapes (texture the
/// estimator must not take for noise).
RadianceImage ramp_with_shapes() {
  const RadianceImage pattern = shapes(3);
  RadianceImage out(kWidth, kHeight);
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; ++c) {
      const float t = float(c) / (kWidth - 1);
      const float level = srgb_to_linear(0.02f + 0.96f * t);
      out(r, c) = (r / 40) % 2 == 0 ? Float3{level, level, level} : pattern(r, c);
    }
  return out;
}

TEST(CameraNoise, EstimatesSigmaPerIntensityBandWithin20Percent) {
  const NoiseProfile profile = estimate_camera_noise(with_noise(ramp_with_shapes(), 7));
  ASSERT_TRUE(profile.valid());
  for (int band = 0; band < kNoiseBands; ++band) {
    if (profile.samples[std::size_t(band)] == 0) continue;
    const double centre = (band + 0.5) * 256.0 / kNoiseBands;
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(profile.sigma[std::size_t(band)][std::size_t(ch)], true_noise(centre), 0.2 * true_noise(centre))
          << "band " << band << " channel " << ch << " (" << profile.samples[std::size_t(band)] << " samples)";
  }
  EXPECT_GE(std::count_if(profile.samples.begin(), profile.samples.end(), [](int n) { return n > 0; }), 6);
}

TEST(CameraNoise, ANoiseFreeImageHasNoNoise) {
  const NoiseProfile profile = estimate_camera_noise(encoded(ramp_with_shapes()));
  ASSERT_TRUE(profile.valid());
  for (const auto& band : profile.sigma)
    for (const float s : band) EXPECT_LT(s, 0.35f);  // 8-bit rounding of a smooth ramp, no more
}

/// A layer: a virtual square of grey `level` over half the image width, nothing else.
VirtualLayer square_layer(float level) {
  VirtualLayer layer{RadianceImage(kWidth, kHeight), Image<float>(kWidth, kHeight), RadianceImage(kWidth, kHeight)};
  for (int r = 60; r < 180; ++r)
    for (int c = 100; c < 220; ++c) {
      layer.coverage(r, c) = 1.f;
      layer.virtual_color(r, c) = {level, level, level};
    }
  return layer;
}

TEST(CameraLookComposite, AnEmptyLayerKeepsTheCameraBitForBit) {
  const ColorImage camera = with_noise(ramp_with_shapes(), 3);
  CameraLook look;
  look.blur_sigma_px = 1.5f;
  look.noise = estimate_camera_noise(camera);
  VirtualLayer layer{RadianceImage(kWidth, kHeight), Image<float>(kWidth, kHeight), RadianceImage(kWidth, kHeight)};
  const ColorImage out = composite_layer(camera, layer, &look);
  EXPECT_TRUE(std::equal(out.pixels().begin(), out.pixels().end(), camera.pixels().begin()));
}

TEST(CameraLookComposite, TheVirtualEdgeGetsTheCamerasProfile) {
  // The camera: the pattern blurred by sigma; the virtual square rendered sharp. With the
  // look's blur the square's edges measure as the camera's do.
  const double sigma = 1.6;
  const ColorImage camera = encoded(blurred(shapes(4), sigma));
  CameraLook look;
  look.artefacts = parse_camera_artefacts("blur");
  look.blur = estimate_camera_blur(camera);
  look.blur_sigma_px = float(std::sqrt(std::max(0.0, look.blur.sigma_px * look.blur.sigma_px - 1.0 / 12.0)));
  const ColorImage plain = composite_layer(ColorImage(kWidth, kHeight, Rgb8{40, 40, 40}), square_layer(0.6f), nullptr);
  const ColorImage filmed = composite_layer(ColorImage(kWidth, kHeight, Rgb8{40, 40, 40}), square_layer(0.6f), &look);
  const BlurEstimate sharp = estimate_camera_blur(plain), soft = estimate_camera_blur(filmed);
  ASSERT_TRUE(soft.valid());
  EXPECT_LT(sharp.sigma_px, 0.5 * soft.sigma_px);  // a pixel-aligned step measures ~0.6 px
  EXPECT_NEAR(soft.sigma_px, look.blur.sigma_px, 0.2 * look.blur.sigma_px) << "camera " << look.blur.sigma_px;
  // The coverage blurs with the colour: the blend stays between the two sides (no halo).
  for (int c = 90; c < 110; ++c) {
    EXPECT_GE(filmed(120, c).r, 40 - 1);
    EXPECT_LE(filmed(120, c).r, plain(120, 150).r + 1);
  }
}

TEST(CameraLookComposite, MotionBlurSmearsTheLayerAlongTheMotion) {
  CameraLook look;
  look.artefacts = parse_camera_artefacts("motion");
  look.motion.motion = Image<Float3>(kWidth / look.motion.cell, kHeight / look.motion.cell, Float3{10.f, 0.f, 0.f});
  const ColorImage background(kWidth, kHeight, Rgb8{40, 40, 40});
  const ColorImage out = composite_layer(background, square_layer(0.6f), &look);
  // Across the motion the left edge ramps over ~10 px; along it (top edge) it stays sharp.
  const double inside = srgb8_to_linear(out(120, 150).r), outside = srgb8_to_linear(40);
  const auto share = [&](int r, int c) { return (srgb8_to_linear(out(r, c).r) - outside) / (inside - outside); };
  EXPECT_GT(share(120, 97), 0.05);
  EXPECT_LT(share(120, 102), 0.95);
  EXPECT_NEAR(share(120, 100), 0.5, 0.2);
  EXPECT_EQ(out(58, 150).r, 40);
  EXPECT_GT(share(61, 150), 0.9);
}

TEST(CameraLookComposite, AHugeOrBrokenMotionIsCutNotAHang) {
  CameraLook look;
  look.artefacts = parse_camera_artefacts("motion");
  look.motion.motion = Image<Float3>(kWidth / look.motion.cell, kHeight / look.motion.cell, Float3{1e9f, 0.f, 0.f});
  look.motion.motion(3, 3) = {std::nanf(""), 0.f, 0.f};
  const ColorImage out = composite_layer(ColorImage(kWidth, kHeight, Rgb8{40, 40, 40}), square_layer(0.6f), &look);
  // The square smears at most kMaxMotionPx / 2 beyond its left edge (column 100).
  EXPECT_EQ(out(120, 100 - static_cast<int>(kMaxMotionPx / 2) - 2).r, 40);
  EXPECT_GT(out(120, 100 - static_cast<int>(kMaxMotionPx / 2) + 4).r, 40);
}

TEST(CameraLookComposite, NoiseMatchesTheProfileAndChangesEveryFrame) {
  CameraLook look;
  look.artefacts = parse_camera_artefacts("noise");
  look.noise = estimate_camera_noise(with_noise(ramp_with_shapes(), 11));
  const ColorImage background(kWidth, kHeight, Rgb8{40, 40, 40});
  for (const float level : {0.05f, 0.2f, 0.6f}) {
    look.seed = 1;
    const ColorImage a = composite_layer(background, square_layer(level), &look);
    look.seed = 2;
    const ColorImage b = composite_layer(background, square_layer(level), &look);
    double sum = 0, squares = 0;
    int n = 0, differ = 0;
    for (int r = 70; r < 170; ++r)
      for (int c = 110; c < 210; ++c) {
        const double v = a(r, c).g;
        sum += v;
        squares += v * v;
        ++n;
        differ += a(r, c).g != b(r, c).g;
      }
    const double mean = sum / n, sd = std::sqrt(squares / n - mean * mean);
    const double expected = true_noise(255.0 * linear_to_srgb(level));
    EXPECT_NEAR(sd, expected, 0.2 * expected) << "level " << level;
    EXPECT_NEAR(mean, 255.0 * linear_to_srgb(level), 0.5);
    EXPECT_GT(differ, n / 3) << "a new pattern every frame";
  }
}

TEST(CameraArtefacts, ParsesTheOptionsList) {
  EXPECT_EQ(parse_camera_artefacts("all"), CameraArtefacts{});
  EXPECT_FALSE(parse_camera_artefacts("none").any());
  const CameraArtefacts some = parse_camera_artefacts("blur,noise");
  EXPECT_TRUE(some.blur && some.noise && !some.motion);
  EXPECT_EQ(to_string(some), "blur,noise");
  EXPECT_THROW((void)parse_camera_artefacts("blur,grain"), Error);
  EXPECT_THROW((void)parse_camera_artefacts(""), Error);
}

}  // namespace
}  // namespace relight::colormap
