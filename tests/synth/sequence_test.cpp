#include "relight/synth/sequence.h"
#include "relight/truth/sequence_writer.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "relight/capture/tum_sequence.h"
#include "relight/capture/tum_writer.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::synth {
namespace {

using Eigen::Vector3d;
using Json = nlohmann::json;
namespace fs = std::filesystem;

SynthOptions small_options() {
  SynthOptions options;
  options.frames = 2;
  options.width = 160;
  options.height = 120;
  return options;
}

std::map<std::string, std::string> folder_contents(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.is_regular_file()) files[fs::relative(entry.path(), folder).string()] = read_text_file(entry.path());
  }
  return files;
}

Vector3d vec(const Json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

TEST(Sequence, WritesATumFolderWithGroundTruthThatTheReaderUnderstands) {
  test::TempDir dir;
  SynthOptions options = small_options();
  options.trajectory = Trajectory::Handheld;
  options.seed = 5;
  int progress_calls = 0;
  truth::write_sequence(options, dir.path(), [&](int done, int total) {
    EXPECT_EQ(total, 2);
    EXPECT_EQ(done, ++progress_calls);
  });
  EXPECT_EQ(progress_calls, 2);

  const capture::TumSequence sequence = capture::TumSequence::open(dir.path());
  ASSERT_EQ(sequence.size(), 2u);
  EXPECT_EQ(sequence.intrinsics(), synth_intrinsics(options));
  EXPECT_DOUBLE_EQ(sequence.depth_scale(), 5000.0);
  const Scene scene = default_indoor_scene();
  const auto poses = make_trajectory(options.trajectory, 2, options.seed, scene);
  ASSERT_TRUE(sequence.frame(1).camera_to_world);
  EXPECT_LT((sequence.frame(1).camera_to_world->translation() - poses[1].translation()).norm(), 1e-5);

  const std::string stem = fs::path(capture::TumWriter::file_name(frame_timestamp(1))).stem().string();
  const RenderedFrame truth = render_frame(scene, synth_intrinsics(options), poses[1], 1);
  EXPECT_TRUE(read_depth_exr(dir.path() / "gt" / "depth" / (stem + ".exr")) == truth.depth);
  EXPECT_TRUE(read_label_png(dir.path() / "gt" / "material" / (stem + ".png")) == truth.material);
  const RadianceImage normals = read_radiance(dir.path() / "gt" / "normals" / (stem + ".exr"));
  EXPECT_EQ(normals(60, 80), truth.normals(60, 80));
  EXPECT_TRUE(read_color(dir.path() / "gt" / "albedo" / (stem + ".png")) == encode_albedo(truth.albedo));
  const RadianceImage probe = read_radiance(dir.path() / "probe.hdr");
  ASSERT_EQ(probe.width(), 512);
  EXPECT_NEAR(probe(256, 256).y, scene.environment.y(), scene.environment.y() / 64.0);  // RGBE precision

  // Noisy depth stays close to the truth where it exists.
  const DepthMap noisy =
      read_depth_png(dir.path() / "depth" / capture::TumWriter::file_name(frame_timestamp(1)), 5000.0);
  int close = 0, valid = 0;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    if (!is_valid_depth(noisy.pixels()[i])) continue;
    ++valid;
    close += std::abs(noisy.pixels()[i] - truth.depth.pixels()[i]) < 0.05f ? 1 : 0;
  }
  // Lateral jitter moves samples across edges and along slanted surfaces, so allow a tail.
  EXPECT_GT(valid, 10000);
  EXPECT_GT(close, 0.9 * valid);
}

TEST(Sequence, SceneJsonDescribesTheScene) {
  test::TempDir dir;
  SynthOptions options = small_options();
  options.frames = 1;
  options.probe = false;
  options.color.gains = {1.1, 1.0, 0.9};
  truth::write_sequence(options, dir.path());
  const Json json = Json::parse(read_text_file(dir.path() / "scene.json"));
  EXPECT_EQ(json["intrinsics"]["width"], 160);
  EXPECT_DOUBLE_EQ(json["intrinsics"]["fx"].get<double>(), 525.0 / 4.0);
  EXPECT_EQ(json["depth_scale"], 5000);
  EXPECT_EQ(vec(json["world_up"]), Vector3d::UnitZ());
  EXPECT_EQ(json["trajectory"], "orbit");
  EXPECT_EQ(json["seed"], 0);
  EXPECT_EQ(json["noise"]["model"], "kinect1");
  EXPECT_DOUBLE_EQ(json["color"]["gains"][0].get<double>(), 1.1);
  EXPECT_EQ(json["tag"]["family"], "tag36h11");
  EXPECT_EQ(json["tag"]["id"], 0);
  EXPECT_DOUBLE_EQ(json["tag"]["size"].get<double>(), 0.16);
  ASSERT_EQ(json["tag"]["corners_world"].size(), 4u);
  EXPECT_NEAR((vec(json["tag"]["corners_world"][0]) - vec(json["tag"]["corners_world"][2])).norm(), 0.16 * std::sqrt(2.0), 1e-12);
  ASSERT_GE(json["lights"].size(), 1u);
  EXPECT_TRUE(json["lights"][0]["real"].get<bool>());
  EXPECT_EQ(json["lights"][0]["type"], "point");
  const auto& materials = json["materials"];
  bool glossy = false;
  for (const auto& m : materials) glossy = glossy || m["ks"].get<double>() >= 0.5;
  EXPECT_TRUE(glossy);
  EXPECT_EQ(materials[0]["id"], 1);
  EXPECT_EQ(json["probe"]["model"], "equidistant");
  EXPECT_EQ(json["probe"]["width"], 512);
  EXPECT_GT(json["objects"].size(), 8u);
  EXPECT_EQ(vec(json["environment"]["radiance"]), default_indoor_scene().environment);
}

TEST(Sequence, SameSeedGivesIdenticalBytesAndAnotherSeedOtherNoise) {
  test::TempDir a, b, c;
  SynthOptions options = small_options();
  options.seed = 17;
  truth::write_sequence(options, a.path());
  options.threads = 1;  // the schedule must not matter either
  truth::write_sequence(options, b.path());
  options.seed = 18;
  truth::write_sequence(options, c.path());
  const auto files_a = folder_contents(a.path());
  const auto files_b = folder_contents(b.path());
  const auto files_c = folder_contents(c.path());
  EXPECT_GT(files_a.size(), 12u);
  EXPECT_TRUE(files_a == files_b);
  const std::string depth = "depth/" + capture::TumWriter::file_name(frame_timestamp(0));
  const std::string rgb = "rgb/" + capture::TumWriter::file_name(frame_timestamp(0));
  EXPECT_NE(files_a.at(depth), files_c.at(depth));
  EXPECT_EQ(files_a.at(rgb), files_c.at(rgb));  // the orbit does not depend on the seed
}

double grey(const Rgb8& c) { return (c.r + c.g + c.b) / 3.0; }

TEST(Sequence, TagCornersProjectWhereSceneJsonSays) {
  test::TempDir dir;
  SynthOptions options;
  options.frames = 1;
  options.trajectory = Trajectory::Static;
  options.noise = NoiseModel::None;
  options.ground_truth = false;
  options.probe = false;
  truth::write_sequence(options, dir.path());
  const Json json = Json::parse(read_text_file(dir.path() / "scene.json"));
  const auto& k = json["intrinsics"];
  const PinholeIntrinsics intrinsics{k["fx"].get<double>(), k["fy"].get<double>(), k["cx"].get<double>(),
                                     k["cy"].get<double>(), k["width"].get<int>(),   k["height"].get<int>()};
  const capture::TumSequence sequence = capture::TumSequence::open(dir.path());
  const Pose world_to_camera = sequence.frame(0).camera_to_world->inverse();
  const ColorImage rgb = read_color(sequence.frame(0).color_file);
  const auto& m = json["tag"]["pose"]["matrix"];
  const Vector3d x_axis{m[0][0].get<double>(), m[1][0].get<double>(), m[2][0].get<double>()};
  const Vector3d y_axis{m[0][1].get<double>(), m[1][1].get<double>(), m[2][1].get<double>()};
  const Vector3d centre = vec(json["tag"]["pose"]["position"]);
  auto colour_at = [&](const Vector3d& world) {
    const Eigen::Vector2d px = intrinsics.project(world_to_camera * world);
    return grey(rgb(static_cast<int>(std::lround(px.y())), static_cast<int>(std::lround(px.x()))));
  };
  for (const auto& corner_json : json["tag"]["corners_world"]) {
    const Vector3d corner = vec(corner_json);
    // Step 6 mm along both tag axes: inwards lands in the 20 mm black border, outwards in the
    // 20 mm white margin.
    const Vector3d inwards = 0.006 * (Vector3d((centre - corner).dot(x_axis) * x_axis).normalized() +
                                      Vector3d((centre - corner).dot(y_axis) * y_axis).normalized());
    EXPECT_LT(colour_at(corner + inwards), 70.0);
    EXPECT_GT(colour_at(corner - inwards), 150.0);
  }
}

TEST(Sequence, RenderedTagDecodesToTag36h11Id0) {
  const Scene scene = default_indoor_scene();
  const TagDecal& tag = scene.tags.front();
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_v1();
  const Pose pose = look_at(tag.centre + Vector3d(0, 0, 0.45), tag.centre, Vector3d::UnitY());
  const ColorImage rgb = encode_color(render_frame(scene, k, pose, 0).radiance);
  const Pose world_to_camera = pose.inverse();
  const auto code = tag36h11_decode([&](int row, int col) {
    const Vector3d p = tag.centre + (col - 2.5) * tag.cell() * tag.x_axis + (row - 2.5) * tag.cell() * tag.y_axis;
    const Eigen::Vector2d px = k.project(world_to_camera * p);
    return grey(rgb(static_cast<int>(std::lround(px.y())), static_cast<int>(std::lround(px.x())))) > 110.0;
  });
  EXPECT_EQ(code, 0xd7e00984bULL);
}

TEST(Sequence, RejectsBadOptions) {
  test::TempDir dir;
  SynthOptions options = small_options();
  options.frames = -1;
  EXPECT_THROW(truth::write_sequence(options, dir.path()), Error);
  options = small_options();
  options.color.gains = {1.0, 0.0, 1.0};
  EXPECT_THROW(truth::write_sequence(options, dir.path()), Error);
}

}  // namespace
}  // namespace relight::synth
