#include "relight/core/image_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "temp_dir.h"

namespace relight {
namespace {

TEST(ImageIo, DepthPngRoundTripAtScale5000) {
  test::TempDir dir;
  DepthMap depth(16, 8);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c) depth(r, c) = 0.5f + 0.1f * static_cast<float>(r * 16 + c) / 7.f;
  depth(0, 0) = 0.f;
  depth(1, 1) = std::numeric_limits<float>::quiet_NaN();
  depth(2, 2) = 20.f;  // beyond 65535 / 5000 = 13.1 m: not representable, stored as missing
  write_depth_png(dir.path() / "d.png", depth, 5000.0);
  const DepthMap back = read_depth_png(dir.path() / "d.png", 5000.0);
  ASSERT_TRUE(back.same_shape(depth));
  EXPECT_EQ(back(0, 0), 0.f);
  EXPECT_EQ(back(1, 1), 0.f);
  EXPECT_EQ(back(2, 2), 0.f);
  for (int r = 3; r < 8; ++r)
    for (int c = 0; c < 16; ++c) EXPECT_NEAR(back(r, c), depth(r, c), 0.5 / 5000.0 + 1e-6);
}

TEST(ImageIo, ColorRoundTripKeepsChannelOrder) {
  test::TempDir dir;
  ColorImage image(3, 2);
  image(0, 0) = {255, 0, 0};
  image(1, 2) = {10, 200, 30};
  write_color(dir.path() / "c.png", image);
  const ColorImage back = read_color(dir.path() / "c.png");
  EXPECT_TRUE(back == image);
}

TEST(ImageIo, RadianceHdrRoundTripWithinRgbePrecision) {
  test::TempDir dir;
  RadianceImage image(4, 4, Float3{0.25f, 1.5f, 40.f});
  image(3, 3) = {1000.f, 0.01f, 0.5f};
  write_radiance(dir.path() / "r.hdr", image);
  const RadianceImage back = read_radiance(dir.path() / "r.hdr");
  ASSERT_TRUE(back.same_shape(image));
  // RGBE shares one exponent per pixel: 8-bit mantissa relative to the largest channel.
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      const Float3 a = image(r, c), b = back(r, c);
      const float peak = std::max({a.x, a.y, a.z});
      EXPECT_NEAR(b.x, a.x, peak / 128.f);
      EXPECT_NEAR(b.y, a.y, peak / 128.f);
      EXPECT_NEAR(b.z, a.z, peak / 128.f);
    }
  }
}

TEST(ImageIo, ExrRoundTripIsExactForHalfRepresentableValues) {
  test::TempDir dir;
  RadianceImage image(5, 3, Float3{0.5f, 2.f, 1024.f});
  write_radiance(dir.path() / "r.exr", image);
  const RadianceImage back = read_radiance(dir.path() / "r.exr");
  EXPECT_TRUE(back == image);
}

TEST(ImageIo, NonFiniteRadianceIsRejectedWithTheFileAndPixel) {
  test::TempDir dir;
  RadianceImage image(5, 3, Float3{0.5f, 2.f, 1024.f});
  image(2, 4).y = std::numeric_limits<float>::quiet_NaN();
  write_radiance(dir.path() / "nan.exr", image);
  try {
    (void)read_radiance(dir.path() / "nan.exr");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nan.exr: pixel (4, 2) is not finite"), std::string::npos) << e.what();
  }
}

TEST(ImageIo, EightBitDepthIsRejectedWithTheFileName) {
  test::TempDir dir;
  const auto path = dir.path() / "eight.png";
  write_color(path, ColorImage(4, 4));
  try {
    (void)read_depth_png(path, 5000.0);
    FAIL();
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("eight.png"), std::string::npos) << message;
    EXPECT_NE(message.find("8-bit"), std::string::npos) << message;
  }
}

TEST(ImageIo, MissingAndCorruptFilesAreErrors) {
  test::TempDir dir;
  EXPECT_THROW((void)read_color(dir.path() / "nope.png"), Error);
  write_file_atomically(dir.path() / "corrupt.png", std::string_view("\x89PNG\r\n\x1a\n garbage"));
  EXPECT_THROW((void)read_color(dir.path() / "corrupt.png"), Error);
  EXPECT_THROW((void)read_depth_png(dir.path() / "corrupt.png", 5000.0), Error);
}

// Found by fuzzing (fuzz/depth_png_fuzzer.cpp): this file, 134 bytes with a DICOM signature
// named depth.png, was handed by OpenCV to GDCM, which aborted the process.
TEST(ImageIo, FilesOfAnotherFormatAreRefusedBeforeDecoding) {
  test::TempDir dir;
  const auto dicom = dir.path() / "depth.png";
  write_file_atomically(dicom, std::string(128, '\xa4') + "DICM1\x01");
  for (const auto& read : {+[](const std::filesystem::path& p) { (void)read_depth_png(p, 5000.0); },
                           +[](const std::filesystem::path& p) { (void)read_label_png(p); },
                           +[](const std::filesystem::path& p) { (void)read_color(p); }}) {
    try {
      read(dicom);
      ADD_FAILURE() << "a DICOM file was decoded";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("depth.png: not a PNG"), std::string::npos) << e.what();
    }
  }
  // Each reader takes its own formats and no other: a PNG is not radiance, an EXR not a colour image.
  write_color(dir.path() / "c.png", ColorImage(4, 2));
  write_radiance(dir.path() / "r.exr", RadianceImage(4, 2));
  EXPECT_NO_THROW((void)read_color(dir.path() / "c.png"));
  EXPECT_NO_THROW((void)read_radiance(dir.path() / "r.exr"));
  EXPECT_THROW((void)read_radiance(dir.path() / "c.png"), Error);
  EXPECT_THROW((void)read_color(dir.path() / "r.exr"), Error);
  EXPECT_THROW((void)read_depth_exr(dir.path() / "c.png"), Error);
}

/// Sets the readers' size limit for one test and restores the default after it.
struct SizeLimitForTest {
  explicit SizeLimitForTest(ImageSizeLimit limit) { set_image_size_limit(limit); }
  ~SizeLimitForTest() { set_image_size_limit({}); }
};

// Issue "huge inputs": a header that claims more than the limit is refused, naming the file, its
// size and the limit, before a decoder allocates (read from the header of PNG, JPEG-less here,
// Radiance HDR and OpenEXR files alike).
TEST(ImageIo, ImagesOverTheSizeLimitAreRefusedFromTheirHeader) {
  test::TempDir dir;
  write_color(dir.path() / "c.png", ColorImage(40, 30));
  write_radiance(dir.path() / "r.hdr", RadianceImage(40, 30));
  write_radiance(dir.path() / "r.exr", RadianceImage(40, 30));
  write_depth_png(dir.path() / "d.png", DepthMap(40, 30), 5000.0);
  const auto expect_refused = [](const std::function<void()>& read, const std::string& message) {
    try {
      read();
      ADD_FAILURE() << "read past the limit: " << message;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  {
    const SizeLimitForTest small({32, 1 << 20});
    expect_refused([&] { (void)read_color(dir.path() / "c.png"); }, "c.png: a 40x30 PNG image, over the limit of 32");
    expect_refused([&] { (void)read_radiance(dir.path() / "r.hdr"); }, "r.hdr: a 40x30 Radiance HDR image");
    expect_refused([&] { (void)read_radiance(dir.path() / "r.exr"); }, "r.exr: a 40x30 OpenEXR image");
    expect_refused([&] { (void)read_depth_png(dir.path() / "d.png", 5000.0); }, "d.png: a 40x30 PNG image");
  }
  {
    const SizeLimitForTest few_pixels({64, 1000});  // 40 x 30 = 1200 pixels
    expect_refused([&] { (void)read_radiance(dir.path() / "r.exr"); }, "and 1000 pixels in all");
  }
  EXPECT_EQ(read_color(dir.path() / "c.png").width(), 40);  // the default limit takes them
  EXPECT_EQ(read_radiance(dir.path() / "r.hdr").height(), 30);
  EXPECT_EQ(read_radiance(dir.path() / "r.exr").width(), 40);
  // A few bytes that claim 100 000 x 100 000 pixels: refused, not allocated.
  write_file_atomically(dir.path() / "huge.hdr",
                        std::string_view("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n"));
  expect_refused([&] { (void)read_radiance(dir.path() / "huge.hdr"); }, "huge.hdr: a 100000x100000 Radiance HDR image");
}

TEST(ImageIo, PreviewsMarkInvalidPixelsBlack) {
  DepthMap depth(2, 1);
  depth(0, 0) = 1.f;
  const ColorImage preview = depth_preview(depth);
  EXPECT_EQ(preview(0, 1), (Rgb8{0, 0, 0}));
  EXPECT_NE(preview(0, 0), (Rgb8{0, 0, 0}));
  NormalMap normals(2, 1);
  normals(0, 0) = {0, 0, -1};
  const ColorImage np = normal_preview(normals);
  EXPECT_EQ(np(0, 0), (Rgb8{128, 128, 255}));
  EXPECT_EQ(np(0, 1), (Rgb8{0, 0, 0}));
}

TEST(ImageIo, DepthExrRoundTripIsExactFloat) {
  test::TempDir dir;
  DepthMap depth(7, 5);
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 7; ++c) depth(r, c) = 0.4f + 0.0001234f * static_cast<float>(r * 7 + c) + 3.f * static_cast<float>(c);
  depth(2, 3) = 0.f;
  write_depth_exr(dir.path() / "d.exr", depth);
  const DepthMap back = read_depth_exr(dir.path() / "d.exr");
  EXPECT_TRUE(back == depth);
  EXPECT_THROW((void)read_depth_exr(dir.path() / "missing.exr"), Error);
  write_color(dir.path() / "c.png", ColorImage(2, 2));
  EXPECT_THROW((void)read_depth_exr(dir.path() / "c.png"), Error);
}

TEST(ImageIo, LabelPngKeepsSixteenBitValues) {
  test::TempDir dir;
  LabelImage labels(4, 3);
  labels(0, 0) = 1;
  labels(1, 2) = 300;
  labels(2, 3) = 65535;
  write_label_png(dir.path() / "l.png", labels);
  EXPECT_TRUE(read_label_png(dir.path() / "l.png") == labels);
}

}  // namespace
}  // namespace relight
