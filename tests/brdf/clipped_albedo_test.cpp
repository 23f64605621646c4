// Where the camera saturates its colour is only a lower bound (diffuse.h): clipped pixels get no
// k_d of their own and take the material of their surface's unclipped parts (fill_clipped_labels).
#include <gtest/gtest.h>

#include <limits>

#include "relight/brdf/brdf_stages.h"
#include "relight/brdf/diffuse.h"

namespace relight::brdf {
namespace {

constexpr int kWidth = 40, kHeight = 20;

/// A plane facing the camera at depth `depth` (camera frame), normals towards the camera.
void plane(PositionMap& positions, NormalMap& normals, int col0, int col1, float depth) {
  for (int r = 0; r < kHeight; ++r)
    for (int c = col0; c < col1; ++c) {
      positions(r, c) = {(c - 20) * 0.01f * depth, (r - 10) * 0.01f * depth, depth};
      normals(r, c) = {0.f, 0.f, -1.f};
    }
}

TEST(ClippedAlbedo, SaturatedPixelsAreMarkedClippedWithoutAnAlbedo) {
  PositionMap positions(kWidth, kHeight);
  NormalMap normals(kWidth, kHeight);
  plane(positions, normals, 0, kWidth, 1.f);
  ColorImage color(kWidth, kHeight, Rgb8{180, 170, 150});
  for (int r = 0; r < kHeight; ++r)
    for (int c = 20; c < kWidth; ++c) color(r, c) = c < 30 ? Rgb8{255, 250, 230} : Rgb8{255, 255, 255};
  ShadingLights lights;
  lights.lights.push_back({false, Eigen::Vector3f(0.f, 0.f, -1.f), Eigen::Vector3f::Constant(3.f)});
  RadianceImage kd;
  Mask valid;
  estimate_diffuse(color, positions, normals, lights, {}, kd, valid);
  EXPECT_TRUE(has_kd(valid(5, 5)));
  EXPECT_GT(kd(5, 5).x, 0.f);
  for (const int c : {20, 29, 35}) {
    EXPECT_EQ(valid(5, c), kKdMarkClipped) << c;
    EXPECT_EQ(kd(5, c), Float3{}) << c;
    EXPECT_FALSE(has_kd(valid(5, c)));
  }
}

TEST(ClippedAlbedo, ClippedPixelsTakeTheLabelOfTheirOwnSurface) {
  // Columns 0-9: surface A (label 1, depth 1 m); 10-29 clipped; 30-39: surface B (label 2).
  // The clipped columns 10-24 lie on A, 25-29 on B (depth 2 m): each takes its surface's label
  // across the clipped area, never the other's across the depth step.
  PositionMap positions(kWidth, kHeight);
  NormalMap normals(kWidth, kHeight);
  plane(positions, normals, 0, 25, 1.f);
  plane(positions, normals, 25, kWidth, 2.f);
  LabelImage ids(kWidth, kHeight);
  Mask valid(kWidth, kHeight, kKdMarkValid);
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < 10; ++c) ids(r, c) = 1;
    for (int c = 10; c < 30; ++c) valid(r, c) = kKdMarkClipped;
    for (int c = 30; c < kWidth; ++c) ids(r, c) = 2;
  }
  ids(0, 5) = 0;  // an unlabelled, unclipped pixel stays unlabelled
  valid(0, 5) = kKdMarkInvalid;
  fill_clipped_labels(ids, valid, positions);
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 10; c < 25; ++c) EXPECT_EQ(ids(r, c), 1) << r << ", " << c;
    for (int c = 25; c < 30; ++c) EXPECT_EQ(ids(r, c), 2) << r << ", " << c;
  }
  EXPECT_EQ(ids(0, 5), 0);
  // A clipped island on a surface of its own, with nothing labelled on it, keeps no label.
  plane(positions, normals, 10, 30, 3.f);
  LabelImage island(kWidth, kHeight);
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < 10; ++c) island(r, c) = 1;
    for (int c = 30; c < kWidth; ++c) island(r, c) = 2;
  }
  fill_clipped_labels(island, valid, positions);
  EXPECT_EQ(island(10, 20), 0);
}

}  // namespace
}  // namespace relight::brdf
