#include "relight/capture/tum_writer.h"

#include <gtest/gtest.h>

#include "relight/capture/tum_sequence.h"
#include "relight/core/error.h"
#include "temp_dir.h"

namespace relight::capture {
namespace {

TEST(TumWriter, WrittenFolderReadsBackIdentically) {
  test::TempDir dir;
  const auto folder = dir.path() / "seq";
  TumWriter writer(folder);
  std::vector<Pose> poses;
  for (int i = 0; i < 3; ++i) {
    ColorImage color(640, 480, Rgb8{static_cast<std::uint8_t>(10 * i), 20, 30});
    DepthMap depth(640, 480, 1.0f + 0.5f * static_cast<float>(i));
    depth(7, 9) = 0.f;
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(0.1 * i, -0.2, 1.5);
    poses.push_back(pose);
    writer.add(1.0 + i / 30.0, color, depth, pose);
  }
  writer.finish();

  const auto sequence = TumSequence::open(folder);
  ASSERT_EQ(sequence.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const RgbdFrame frame = sequence.load(i);
    EXPECT_EQ(frame.color(100, 100).r, 10 * i);
    EXPECT_NEAR(frame.depth(100, 100), 1.0f + 0.5f * static_cast<float>(i), 1e-4);
    EXPECT_EQ(frame.depth(7, 9), 0.f);
    ASSERT_TRUE(frame.info.camera_to_world.has_value());
    EXPECT_NEAR((frame.info.camera_to_world->translation() - poses[i].translation()).norm(), 0.0, 1e-6);
    EXPECT_NEAR(rotation_distance(*frame.info.camera_to_world, poses[i]), 0.0, 1e-6);
  }
}

TEST(TumWriter, RejectsNonIncreasingTimestamps) {
  test::TempDir dir;
  TumWriter writer(dir.path() / "seq");
  writer.add(1.0, ColorImage(2, 2), DepthMap(2, 2));
  EXPECT_THROW(writer.add(1.0, ColorImage(2, 2), DepthMap(2, 2)), Error);
}

TEST(TumWriter, FileNamesUseSixDecimals) { EXPECT_EQ(TumWriter::file_name(1.0 + 1.0 / 30.0), "1.033333.png"); }

}  // namespace
}  // namespace relight::capture
