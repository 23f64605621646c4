#include "relight/core/image.h"

#include <gtest/gtest.h>

#include <limits>
#include <type_traits>

namespace relight {
namespace {

TEST(Image, RowMajorLayoutWithRowColIndexing) {
  Image<int> image(3, 2);
  image(1, 2) = 7;
  EXPECT_EQ(image.width(), 3);
  EXPECT_EQ(image.height(), 2);
  EXPECT_EQ(image.data()[1 * 3 + 2], 7);
  EXPECT_EQ(image.row(1)[2], 7);
  EXPECT_TRUE(image.in_bounds(1, 2));
  EXPECT_FALSE(image.in_bounds(2, 1));
  EXPECT_FALSE(image.in_bounds(-1, 0));
}

TEST(Image, DomainTypesAreDistinctButShareTheirBase) {
  static_assert(!std::is_same_v<NormalMap, PositionMap>);
  static_assert(std::is_base_of_v<Image<Float3>, NormalMap>);
  static_assert(std::is_trivially_copyable_v<Float3>);
  static_assert(sizeof(Rgb8) == 3 && sizeof(Float3) == 12);
  NormalMap normals(2, 2, Float3{0, 0, -1});
  const Image<Float3>& base = normals;
  EXPECT_EQ(base(1, 1), (Float3{0, 0, -1}));
  EXPECT_EQ(normals.bytes().size(), 4 * sizeof(Float3));
}

TEST(Image, ValidityHelpers) {
  EXPECT_TRUE(is_valid_depth(0.7f));
  EXPECT_FALSE(is_valid_depth(0.f));
  EXPECT_FALSE(is_valid_depth(-1.f));
  EXPECT_FALSE(is_valid_depth(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_FALSE(is_valid_depth(std::numeric_limits<float>::infinity()));
  EXPECT_TRUE(is_valid_normal({0, 0, 1}));
  EXPECT_FALSE(is_valid_normal({0, 0, 0}));
  EXPECT_FALSE(is_valid_normal({std::numeric_limits<float>::quiet_NaN(), 0, 1}));
}

TEST(Image, ResizeAndFill) {
  DepthMap depth;
  EXPECT_TRUE(depth.empty());
  depth.resize(5, 4);
  depth.fill(1.5f);
  EXPECT_EQ(depth.size(), 20u);
  EXPECT_FLOAT_EQ(depth(3, 4), 1.5f);
  DepthMap other(5, 4, 1.5f);
  EXPECT_TRUE(depth == other);
  other(0, 0) = 2.f;
  EXPECT_FALSE(depth == other);
}

}  // namespace
}  // namespace relight
