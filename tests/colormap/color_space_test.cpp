// sRGB / XYZ / CIELab (illuminant E): the matrices come from the sRGB primaries, white maps to
// L* = 100 neutral, the conversions round-trip, and the sRGB curve matches IEC 61966-2-1.
#include "relight/colormap/color_space.h"

#include <gtest/gtest.h>

#include <cmath>

namespace relight::colormap {
namespace {

TEST(ColorSpace, MatrixColumnsHaveTheSrgbPrimaryChromaticities) {
  const double primaries[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
  for (int c = 0; c < 3; ++c) {
    const double x = kLinearSrgbToXyzE[0][c], y = kLinearSrgbToXyzE[1][c], z = kLinearSrgbToXyzE[2][c];
    EXPECT_NEAR(x / (x + y + z), primaries[c][0], 1e-6) << "primary " << c;
    EXPECT_NEAR(y / (x + y + z), primaries[c][1], 1e-6) << "primary " << c;
  }
}

TEST(ColorSpace, InverseMatrixIsTheInverse) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (int k = 0; k < 3; ++k) sum += double(kXyzEToLinearSrgb[r][k]) * kLinearSrgbToXyzE[k][c];
      EXPECT_NEAR(sum, r == c ? 1.0 : 0.0, 1e-6);
    }
  }
}

TEST(ColorSpace, WhiteIsIlluminantEAndNeutral) {
  const Float3 xyz = linear_srgb_to_xyz({1.f, 1.f, 1.f});
  EXPECT_NEAR(xyz.x, 1.f, 1e-6f);
  EXPECT_NEAR(xyz.y, 1.f, 1e-6f);
  EXPECT_NEAR(xyz.z, 1.f, 1e-6f);
  const LabPixel white = linear_srgb_to_lab({1.f, 1.f, 1.f});
  EXPECT_NEAR(white.x, 100.f, 1e-4f);
  EXPECT_NEAR(white.y, 0.f, 1e-4f);
  EXPECT_NEAR(white.z, 0.f, 1e-4f);
  const LabPixel black = linear_srgb_to_lab({0.f, 0.f, 0.f});
  EXPECT_NEAR(black.x, 0.f, 1e-4f);
}

TEST(ColorSpace, GreysFollowTheCieLightnessFormula) {
  // Any grey is neutral under illuminant E; L* = 116 Y^(1/3) - 16 above the linear toe.
  for (const float grey : {0.01f, 0.125f, 0.18f, 0.5f, 0.9f}) {
    const LabPixel lab = linear_srgb_to_lab({grey, grey, grey});
    EXPECT_NEAR(lab.x, 116.0 * std::cbrt(grey) - 16.0, 1e-3) << grey;
    EXPECT_NEAR(lab.y, 0.f, 1e-3f) << grey;
    EXPECT_NEAR(lab.z, 0.f, 1e-3f) << grey;
  }
  // Below (6/29)^3 the linear branch: L* = 903.3 Y.
  EXPECT_NEAR(linear_srgb_to_lab({0.001f, 0.001f, 0.001f}).x, 24389.0 / 27.0 * 0.001, 1e-4);
}

TEST(ColorSpace, LabRoundTripsIncludingOutOfGamutColours) {
  float worst = 0.f;
  for (float r = -0.2f; r <= 1.5f; r += 0.1f) {
    for (float g = -0.2f; g <= 1.5f; g += 0.1f) {
      for (float b = -0.2f; b <= 1.5f; b += 0.1f) {
        const Float3 back = lab_to_linear_srgb(linear_srgb_to_lab({r, g, b}));
        worst = std::max({worst, std::fabs(back.x - r), std::fabs(back.y - g), std::fabs(back.z - b)});
      }
    }
  }
  EXPECT_LT(worst, 2e-5f);
}

TEST(ColorSpace, SrgbCurveMatchesTheStandardAndRoundTrips8Bit) {
  EXPECT_FLOAT_EQ(srgb8_to_linear(0), 0.f);
  EXPECT_FLOAT_EQ(srgb8_to_linear(255), 1.f);
  EXPECT_NEAR(srgb8_to_linear(128), 0.2158605f, 1e-6f);  // ((128/255 + 0.055)/1.055)^2.4
  EXPECT_NEAR(srgb8_to_linear(10), 10.0 / 255.0 / 12.92, 1e-7);  // linear toe
  for (int v = 0; v < 256; ++v) {
    const auto byte = static_cast<std::uint8_t>(v);
    EXPECT_EQ(encode_srgb8({srgb8_to_linear(byte), 0.f, 0.f}).r, byte);
    EXPECT_NEAR(srgb_to_linear(v / 255.f), srgb8_to_linear(byte), 1e-6f);
  }
  EXPECT_EQ(encode_srgb8({-1.f, 2.f, 0.5f}), (Rgb8{0, 255, 188}));  // clamped; linear 0.5 -> 187.52
}

// The encoder searches thresholds instead of calling pow; it must give pow's byte for every
// float: at each threshold and its neighbouring floats, and for a million random values.
TEST(ColorSpace, EncodingBySearchGivesTheBytePowGives) {
  const auto by_pow = [](float c) { return static_cast<int>(std::lround(255.f * linear_to_srgb(c))); };
  for (int v = 0; v < 256; ++v) {
    float x = srgb8_to_linear(static_cast<std::uint8_t>(v));
    for (int step = 0; step < 4; ++step) x = std::nextafter(x, -1.f);
    for (int step = 0; step < 8; ++step, x = std::nextafter(x, 2.f)) ASSERT_EQ(encode_srgb8_channel(x), by_pow(x)) << x;
    // Half-way between codes, where rounding flips.
    float mid = srgb_to_linear((static_cast<float>(v) + 0.5f) / 255.f);
    for (int step = 0; step < 4; ++step) mid = std::nextafter(mid, -1.f);
    for (int step = 0; step < 8; ++step, mid = std::nextafter(mid, 2.f))
      ASSERT_EQ(encode_srgb8_channel(mid), by_pow(mid)) << mid;
  }
  std::uint64_t state = 12345;
  for (int i = 0; i < 1000000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const float x = static_cast<float>(static_cast<double>(state >> 11) * 0x1.0p-53 * 1.2 - 0.1);
    ASSERT_EQ(encode_srgb8_channel(x), by_pow(x)) << x;
  }
  EXPECT_EQ(encode_srgb8_channel(std::nanf("")), 0);
}

}  // namespace
}  // namespace relight::colormap
