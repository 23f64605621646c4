// modulate_camera_albedo (camera_albedo.h) on a hand-built G-buffer: which pixels it changes,
// and by how much.
#include "relight/render/dir/camera_albedo.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

constexpr int kPixels = 6;

/// Everything modulate_camera_albedo reads and writes, `width` x `height`, all zero.
struct Fixture {
  Fixture(int width, int height)
      : gbuffer{PositionMap(width, height), NormalMap(width, height), LabelImage(width, height), Mask(width, height),
                DepthMap(width, height)},
        images{RadianceImage(width, height), RadianceImage(width, height), CoverageImage(width, height), 1,
               RadianceImage(width, height), RadianceImage(width, height)},
        albedo(width, height),
        valid(width, height) {}
  MrScene scene;
  GBuffer gbuffer;
  DifferentialImages images;
  RadianceImage albedo;
  Mask valid;
};

// Pixels: 0 real diffuse; 1 virtual; 2 real glossy; 3 real diffuse, estimate invalid;
// 4 nothing seen; 5 real diffuse whose cluster has no blue.
Fixture fixture() {
  Fixture f(kPixels, 1);
  const std::uint32_t grey = f.scene.add_material(test::diffuse({0.5f, 0.5f, 0.5f}, "grey"));
  PhongMaterial glossy = test::diffuse({0.5f, 0.5f, 0.5f}, "glossy");
  glossy.ks = 0.3f;
  glossy.n = 20.f;
  const std::uint32_t shiny = f.scene.add_material(glossy);
  const std::uint32_t yellow = f.scene.add_material(test::diffuse({0.6f, 0.6f, 0.f}, "yellow"));
  const std::uint16_t labels[kPixels] = {static_cast<std::uint16_t>(grey + 1), static_cast<std::uint16_t>(grey + 1),
                                         static_cast<std::uint16_t>(shiny + 1), static_cast<std::uint16_t>(grey + 1), 0,
                                         static_cast<std::uint16_t>(yellow + 1)};
  for (int x = 0; x < kPixels; ++x) {
    f.gbuffer.material(0, x) = labels[x];
    f.gbuffer.distance(0, x) = labels[x] ? 1.f : 0.f;
    f.gbuffer.virtual_surface(0, x) = x == 1 ? 1 : 0;
    f.valid(0, x) = x == 3 ? 0 : 1;
    f.albedo(0, x) = {0.25f, 0.5f, 0.75f};
    f.images.real(0, x) = {1.f, 2.f, 3.f};
    f.images.real_virtual(0, x) = {0.5f, 1.f, 1.5f};
    f.images.indirect_real(0, x) = {0.1f, 0.2f, 0.3f};
    f.images.indirect_real_virtual(0, x) = {0.05f, 0.1f, 0.15f};
  }
  return f;
}

void expect_rgb(const Float3& got, float r, float g, float b, int pixel) {
  EXPECT_NEAR(got.x, r, 1e-6f) << "pixel " << pixel;
  EXPECT_NEAR(got.y, g, 1e-6f) << "pixel " << pixel;
  EXPECT_NEAR(got.z, b, 1e-6f) << "pixel " << pixel;
}

TEST(CameraAlbedo, ScalesEveryPartOfRealDiffusePixelsByTheirAlbedoOverTheClusters) {
  Fixture f = fixture();
  modulate_camera_albedo(f.images, f.gbuffer, f.scene, f.albedo, f.valid);
  // Pixel 0: factors (0.25, 0.5, 0.75) / 0.5 = (0.5, 1, 1.5) on all four parts.
  expect_rgb(f.images.real(0, 0), 0.5f, 2.f, 4.5f, 0);
  expect_rgb(f.images.real_virtual(0, 0), 0.25f, 1.f, 2.25f, 0);
  expect_rgb(f.images.indirect_real(0, 0), 0.05f, 0.2f, 0.45f, 0);
  expect_rgb(f.images.indirect_real_virtual(0, 0), 0.025f, 0.1f, 0.225f, 0);
  // Virtual, glossy, invalid and empty pixels keep their shading.
  for (int x : {1, 2, 3, 4}) {
    expect_rgb(f.images.real(0, x), 1.f, 2.f, 3.f, x);
    expect_rgb(f.images.real_virtual(0, x), 0.5f, 1.f, 1.5f, x);
    expect_rgb(f.images.indirect_real(0, x), 0.1f, 0.2f, 0.3f, x);
  }
  // Pixel 5: the cluster has no blue to scale, so blue keeps the cluster's shading.
  expect_rgb(f.images.real(0, 5), 0.25f / 0.6f, 2.f * 0.5f / 0.6f, 3.f, 5);
}

// The estimate is averaged over the 5 x 5 window of its own material: a checkerboard of two
// estimates becomes their mean inside a material, and the neighbouring material stays apart.
TEST(CameraAlbedo, EstimatesAreAveragedOverTheirMaterialsWindow) {
  constexpr int kSize = 9;
  Fixture f(kSize, kSize);
  const std::uint32_t left = f.scene.add_material(test::diffuse({0.5f, 0.5f, 0.5f}, "left"));
  const std::uint32_t right = f.scene.add_material(test::diffuse({0.5f, 0.5f, 0.5f}, "right"));
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const bool is_left = x < 5;
      f.gbuffer.material(y, x) = static_cast<std::uint16_t>((is_left ? left : right) + 1);
      f.valid(y, x) = 1;
      const float a = is_left ? ((x + y) % 2 ? 0.2f : 0.4f) : 0.8f;
      f.albedo(y, x) = {a, a, a};
      f.images.real(y, x) = {1.f, 1.f, 1.f};
      f.images.real_virtual(y, x) = {1.f, 1.f, 1.f};
    }
  modulate_camera_albedo(f.images, f.gbuffer, f.scene, f.albedo, f.valid);
  // Centre of the left material: 13 of the 25 window pixels hold 0.4, 12 hold 0.2.
  EXPECT_NEAR(f.images.real(4, 2).x, (13 * 0.4f + 12 * 0.2f) / 25.f / 0.5f, 1e-5f);
  // Its border column (x = 4) averages left pixels only; the right material keeps 0.8.
  EXPECT_NEAR(f.images.real(4, 4).x, (8 * 0.4f + 7 * 0.2f) / 15.f / 0.5f, 1e-5f);
  EXPECT_NEAR(f.images.real(4, 5).x, 0.8f / 0.5f, 1e-5f);
}

TEST(CameraAlbedo, ImagesOfDifferentSizesAreAnError) {
  Fixture f = fixture();
  const RadianceImage small(kPixels - 1, 1);
  EXPECT_THROW(modulate_camera_albedo(f.images, f.gbuffer, f.scene, small, f.valid), Error);
}

}  // namespace
}  // namespace relight::render
