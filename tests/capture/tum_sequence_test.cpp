#include "relight/capture/tum_sequence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::capture {
namespace {

const std::filesystem::path kRealSlice = std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy";

TEST(TumSequence, ReadsTheRealFreiburg1Slice) {
  const TumSequence sequence = TumSequence::open(kRealSlice);
  ASSERT_EQ(sequence.size(), 4u);
  EXPECT_EQ(sequence.intrinsics(), PinholeIntrinsics::kinect_v1());  // TUM's advice for registered depth
  EXPECT_NEAR(sequence.frame(0).depth_timestamp, 1305031229.528784, 1e-6);
  EXPECT_NEAR(sequence.frame(0).color_timestamp, 1305031229.528748, 1e-6);
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    EXPECT_LT(std::abs(sequence.frame(i).depth_timestamp - sequence.frame(i).color_timestamp), 0.02);
    EXPECT_TRUE(sequence.frame(i).camera_to_world.has_value()) << i;
  }
  const RgbdFrame frame = sequence.load(0);
  EXPECT_EQ(frame.depth.width(), 640);
  EXPECT_EQ(frame.color.height(), 480);
  std::vector<float> valid;
  for (float d : frame.depth.pixels()) {
    if (is_valid_depth(d)) valid.push_back(d);
  }
  // An office desk seen by a Kinect: most pixels measured, at plausible ranges.
  EXPECT_GT(valid.size(), frame.depth.size() / 2);
  std::nth_element(valid.begin(), valid.begin() + static_cast<long>(valid.size() / 2), valid.end());
  const float median = valid[valid.size() / 2];
  EXPECT_GT(median, 0.5f);
  EXPECT_LT(median, 4.0f);
}

TEST(TumSequence, InterpolatesGroundTruthAtTheDepthTimestamp) {
  const TumSequence sequence = TumSequence::open(kRealSlice);
  const auto trajectory = read_tum_trajectory(kRealSlice / "groundtruth.txt");
  const Timestamp t = sequence.frame(1).depth_timestamp;
  const auto after = std::find_if(trajectory.begin(), trajectory.end(), [&](auto& e) { return e.first > t; });
  ASSERT_NE(after, trajectory.begin());
  ASSERT_NE(after, trajectory.end());
  const auto& before = *std::prev(after);
  const Pose& pose = *sequence.frame(1).camera_to_world;
  // The interpolated translation lies on the segment between the two bracketing poses.
  const Eigen::Vector3d a = before.second.translation(), b = after->second.translation();
  const double alpha = (t - before.first) / (after->first - before.first);
  EXPECT_NEAR((pose.translation() - (a + alpha * (b - a))).norm(), 0.0, 1e-9);
  EXPECT_LE(rotation_distance(pose, before.second), rotation_distance(before.second, after->second) + 1e-9);
}

TEST(TumAssociate, GreedyNearestWithinTheWindowUsesEachImageOnce) {
  const std::vector<TumEntry> depth{{1.000, "a"}, {1.033, "b"}, {1.066, "c"}, {2.000, "d"}};
  const std::vector<TumEntry> rgb{{1.010, "x"}, {1.030, "y"}, {1.500, "z"}};
  const auto matches = associate(depth, rgb, 0.02);
  // 1.033<->1.030 (0.003) is taken first, so 1.000 gets 1.010 and 1.066 gets nothing.
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[0], (std::pair<std::size_t, std::size_t>{0, 0}));
  EXPECT_EQ(matches[1], (std::pair<std::size_t, std::size_t>{1, 1}));
}

TEST(TumPoseAt, OutsideTheTrajectoryThereIsNoPose) {
  std::vector<std::pair<Timestamp, Pose>> trajectory{{1.0, Pose::Identity()}, {2.0, Pose::Identity()}};
  trajectory[1].second.translation() = Eigen::Vector3d(2, 0, 0);
  EXPECT_FALSE(pose_at(trajectory, 0.5).has_value());
  EXPECT_FALSE(pose_at(trajectory, 2.5).has_value());
  EXPECT_NEAR(pose_at(trajectory, 1.25)->translation().x(), 0.5, 1e-12);
  EXPECT_NEAR(pose_at(trajectory, 2.0)->translation().x(), 2.0, 1e-12);
}

// Copies the real slice into a scratch folder so that a test can damage it.
class DamagedSequence : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = dir_.path() / "seq";
    std::filesystem::copy(kRealSlice, folder_, std::filesystem::copy_options::recursive);
  }
  void replace_line(const std::string& list, int line_number, const std::string& text) {
    std::ifstream in(folder_ / list);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    lines.at(static_cast<std::size_t>(line_number - 1)) = text;
    std::string joined;
    for (const auto& line : lines) joined += line + "\n";
    write_file_atomically(folder_ / list, joined);
  }
  std::string open_error(const TumOptions& options = {}) {
    try {
      const auto sequence = TumSequence::open(folder_, options);
      for (std::size_t i = 0; i < sequence.size(); ++i) (void)sequence.load(i);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
  test::TempDir dir_;
  std::filesystem::path folder_;
};

TEST_F(DamagedSequence, MissingFolder) {
  std::filesystem::remove_all(folder_);
  EXPECT_NE(open_error().find("does not exist"), std::string::npos);
}

TEST_F(DamagedSequence, MissingList) {
  std::filesystem::remove(folder_ / "depth.txt");
  EXPECT_NE(open_error().find("depth.txt"), std::string::npos);
}

TEST_F(DamagedSequence, MalformedLineNamesFileAndLine) {
  replace_line("rgb.txt", 5, "1305031229.564425");  // filename missing
  const std::string message = open_error();
  EXPECT_NE(message.find("rgb.txt:5:"), std::string::npos) << message;
  EXPECT_NE(message.find("expected 'timestamp filename'"), std::string::npos) << message;
}

TEST_F(DamagedSequence, NonNumericTimestamp) {
  replace_line("depth.txt", 4, "12x45 depth/1305031229.528784.png");
  EXPECT_NE(open_error().find("depth.txt:4:"), std::string::npos);
}

TEST_F(DamagedSequence, UnsortedLinesAreRejected) {
  replace_line("rgb.txt", 5, "1305031229.400000 rgb/1305031229.564425.png");
  const std::string message = open_error();
  EXPECT_NE(message.find("rgb.txt:5:"), std::string::npos) << message;
  EXPECT_NE(message.find("not increasing"), std::string::npos) << message;
}

TEST_F(DamagedSequence, MalformedGroundTruth) {
  replace_line("groundtruth.txt", 4, "1305031229.4 1 2 3 0 0 0");
  EXPECT_NE(open_error().find("groundtruth.txt:4:"), std::string::npos);
}

TEST_F(DamagedSequence, MissingImage) {
  std::filesystem::remove(folder_ / "depth" / "1305031229.596617.png");
  const std::string message = open_error();
  EXPECT_NE(message.find("1305031229.596617.png"), std::string::npos) << message;
}

TEST_F(DamagedSequence, MissingImageIsSkippedWhenAskedWithItsIndex) {
  std::filesystem::remove(folder_ / "depth" / "1305031229.596617.png");
  TumSource strict(TumSequence::open(folder_));
  std::string error;
  try {
    while (strict.next()) {
    }
  } catch (const Error& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("1305031229.596617.png"), std::string::npos) << error;

  TumSource lenient(TumSequence::open(folder_));
  std::vector<std::pair<std::size_t, std::string>> skipped;
  lenient.on_bad_frame([&](std::size_t index, const std::string& message) { skipped.emplace_back(index, message); });
  std::vector<std::int64_t> read;
  while (auto frame = lenient.next()) read.push_back(frame->info.index);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].second.find("1305031229.596617.png"), std::string::npos);
  EXPECT_EQ(read.size() + 1, TumSequence::open(folder_).size());
  EXPECT_EQ(std::count(read.begin(), read.end(), static_cast<std::int64_t>(skipped[0].first)), 0);
}

TEST_F(DamagedSequence, CorruptImage) {
  const auto file = folder_ / "rgb" / "1305031229.564425.png";
  const std::string bytes = read_text_file(file);
  write_file_atomically(file, std::string_view(bytes).substr(0, bytes.size() / 3));
  const std::string message = open_error();
  EXPECT_NE(message.find("1305031229.564425.png"), std::string::npos) << message;
}

TEST_F(DamagedSequence, EightBitDepth) {
  write_color(folder_ / "depth" / "1305031229.528784.png", ColorImage(640, 480));
  const std::string message = open_error();
  EXPECT_NE(message.find("8-bit"), std::string::npos) << message;
}

TEST_F(DamagedSequence, DepthWithoutAnyValidPixel) {
  write_depth_png(folder_ / "depth" / "1305031229.564442.png", DepthMap(640, 480, 0.f), 5000.0);
  const std::string message = open_error();
  EXPECT_NE(message.find("1305031229.564442.png: no valid depth"), std::string::npos) << message;
}

TEST_F(DamagedSequence, NothingAssociates) {
  replace_line("depth.txt", 4, "1305031200.0 depth/1305031229.528784.png");
  replace_line("depth.txt", 5, "1305031200.1 depth/1305031229.564442.png");
  replace_line("depth.txt", 6, "1305031200.2 depth/1305031229.596617.png");
  replace_line("depth.txt", 7, "1305031200.3 depth/1305031229.628790.png");
  EXPECT_NE(open_error().find("no colour/depth pair"), std::string::npos);
}

TEST_F(DamagedSequence, SizeMismatchWithIntrinsics) {
  TumOptions options;
  options.intrinsics = PinholeIntrinsics{300, 300, 159.5, 119.5, 320, 240};
  EXPECT_NE(open_error(options).find("does not match the intrinsics"), std::string::npos);
}

TEST_F(DamagedSequence, SceneJsonIntrinsicsWin) {
  write_file_atomically(folder_ / "scene.json",
                        std::string_view(R"({"intrinsics": {"fx": 600, "fy": 601, "cx": 320, "cy": 240,
                                             "width": 640, "height": 480}, "depth_scale": 5000})"));
  const auto sequence = TumSequence::open(folder_);
  EXPECT_DOUBLE_EQ(sequence.intrinsics().fy, 601.0);
  EXPECT_EQ(sequence.intrinsics_source(), "scene.json");
  write_file_atomically(folder_ / "scene.json", std::string_view("{ not json"));
  EXPECT_NE(open_error().find("scene.json"), std::string::npos);
}

// Valid JSON of the wrong shape used to escape as a JSON library exception (found by fuzzing).
TEST_F(DamagedSequence, SceneJsonOfTheWrongShapeIsAnErrorNamingIt) {
  for (const char* scene : {R"(1.05)", R"({"depth_scale": "5000"})", R"({"depth_scale": 0})",
                            R"({"intrinsics": {"fx": 600, "fy": 600, "cx": 320, "cy": 240, "width": 1e300}})",
                            R"({"intrinsics": {"fx": 600, "fy": 600, "cx": 320, "cy": 240, "height": 479.5}})",
                            R"({"intrinsics": {"fx": 0, "fy": 600, "cx": 320, "cy": 240}})"}) {
    write_file_atomically(folder_ / "scene.json", std::string_view(scene));
    const std::string message = open_error();
    EXPECT_NE(message.find("scene.json"), std::string::npos) << scene << ": " << message;
  }
}

TEST(TumSource, RangeSelectsFramesAndRejectsEmptyRanges) {
  TumSource source(TumSequence::open(kRealSlice), 1, 3);
  EXPECT_EQ(source.size_hint(), 2);
  auto first = source.next();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->info.index, 0);
  EXPECT_NEAR(first->info.timestamp, 1305031229.564442, 1e-6);
  EXPECT_TRUE(source.next().has_value());
  EXPECT_FALSE(source.next().has_value());
  EXPECT_THROW(TumSource(TumSequence::open(kRealSlice), 4, 10), Error);
}

}  // namespace
}  // namespace relight::capture
