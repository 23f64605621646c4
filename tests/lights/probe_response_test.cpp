// 8-bit probes: the inverse response, the expansion of saturated pixels and the curve files.
#include "relight/lights/probe_response.h"

#include <gtest/gtest.h>

#include <fstream>

#include "relight/core/error.h"
#include "temp_dir.h"

namespace relight::lights {
namespace {

ColorImage uniform(Rgb8 value, int width = 4, int height = 2) {
  ColorImage image(width, height);
  for (Rgb8& p : image.pixels()) p = value;
  return image;
}

TEST(ProbeResponse, SrgbDecodingIsTheStandardCurve) {
  const auto inverse = ProbeResponse::srgb_inverse();
  EXPECT_FLOAT_EQ(inverse[0][0], 0.f);
  EXPECT_FLOAT_EQ(inverse[1][255], 1.f);
  EXPECT_NEAR(inverse[2][128], 0.2158605, 1e-6);            // ((128/255 + 0.055) / 1.055)^2.4
  EXPECT_NEAR(inverse[0][10], 10.0 / 255.0 / 12.92, 1e-7);  // the linear toe
}

TEST(ProbeResponse, ExposureDividesAndUnclippedPixelsAreNotExpanded) {
  ProbeResponse response;
  response.exposure = 2.0;
  const LdrProbe probe = radiance_from_ldr(uniform({128, 64, 0}), response);
  EXPECT_NEAR(probe.radiance(0, 0).x, 0.2158605 / 2.0, 1e-6);
  EXPECT_NEAR(probe.radiance(1, 3).y, response.inverse[1][64] / 2.0, 1e-7);
  EXPECT_EQ(probe.radiance(0, 1).z, 0.f);
  EXPECT_EQ(probe.clipped_share, 0.0);
}

TEST(ProbeResponse, SaturatedPixelsAreExpandedSmoothly) {
  ProbeResponse response;
  response.clip_gain = 16.0;
  response.clip_threshold = 0.9;
  ColorImage image = uniform({100, 100, 100});
  image(0, 0) = {255, 255, 255};  // fully saturated: gain 16
  image(0, 1) = {255, 200, 10};   // brightest channel saturated: the whole pixel is scaled
  const double m = 240.0 / 255.0;
  image(0, 2) = {240, 240, 240};  // just above the threshold: a small gain
  const LdrProbe probe = radiance_from_ldr(image, response);
  EXPECT_NEAR(probe.radiance(0, 0).x, 16.0, 1e-5);
  EXPECT_NEAR(probe.radiance(0, 1).y, 16.0 * response.inverse[1][200], 1e-5);
  const double s = (m - 0.9) / 0.1;
  EXPECT_NEAR(probe.radiance(0, 2).z, response.inverse[2][240] * (1.0 + 15.0 * s * s), 1e-5);
  EXPECT_NEAR(probe.radiance(1, 0).x, response.inverse[0][100], 1e-7);
  EXPECT_DOUBLE_EQ(probe.clipped_share, 3.0 / 8.0);
}

TEST(ProbeResponse, BadParametersAreErrors) {
  ProbeResponse response;
  response.exposure = 0.0;
  EXPECT_THROW((void)radiance_from_ldr(uniform({1, 1, 1}), response), Error);
  response = {};
  response.clip_threshold = 1.0;
  EXPECT_THROW((void)radiance_from_ldr(uniform({1, 1, 1}), response), Error);
}

TEST(ProbeResponse, CurveFileIsReadAndCheckedLineByLine) {
  test::TempDir dir;
  const auto path = dir.path() / "response.txt";
  {
    std::ofstream out(path);
    out << "# a gamma-2 camera\n";
    for (int code = 0; code < 256; ++code) {
      const double v = (code / 255.0) * (code / 255.0);
      out << v << " " << v << " " << 2 * v << "\n";
    }
  }
  const ProbeResponse response = read_probe_response(path);
  EXPECT_NEAR(response.inverse[0][51], 0.04, 1e-6);
  EXPECT_NEAR(response.inverse[2][255], 2.0, 1e-6);

  {
    std::ofstream out(path);
    for (int code = 0; code < 256; ++code) out << (code == 100 ? 0.0 : code / 255.0) << " 0 0\n";
  }
  try {
    (void)read_probe_response(path);
    FAIL() << "a decreasing curve was accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("line 101"), std::string::npos) << error.what();
  }
  {
    std::ofstream out(path);
    out << "0 0 0\n1 1 1\n";
  }
  EXPECT_THROW((void)read_probe_response(path), Error);
  EXPECT_THROW((void)read_probe_response(dir.path() / "missing.txt"), Error);
}

}  // namespace
}  // namespace relight::lights
