// Objects placed on real surfaces (`--place-at`, `--place-on-plane`) through `relight replay`:
// the main job's pebble on the embedded TUM sample's desk, a pixel's surface and the support
// plane of a synthetic sequence measured against its exact geometry, and one-line errors for
// placements that cannot be resolved.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/core/camera.h"
#include "relight/core/image_io.h"
#include "relight/core/pose.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

const std::filesystem::path kData = RELIGHT_TEST_DATA;
const std::string kPebble = (kData / "models" / "glossy_pebble.gltf").string();

/// The first pose of a TUM trajectory file (groundtruth.txt, camera_trajectory.txt).
Pose first_pose(const std::filesystem::path& file) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double timestamp = 0;
    std::array<double, 7> pose{};
    fields >> timestamp;
    for (double& v : pose) fields >> v;
    return pose_from_tum(pose);
  }
  ADD_FAILURE() << "no pose in " << file;
  return Pose::Identity();
}

nlohmann::json placement_of(const std::filesystem::path& out) {
  const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
  EXPECT_EQ(report["placements"].size(), 1u) << report.dump();
  return report["placements"][0];
}

Eigen::Vector3d vector_of(const nlohmann::json& json) {
  return Eigen::Vector3d(json[0].get<double>(), json[1].get<double>(), json[2].get<double>());
}

double degrees_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

/// Pixels within `radius` of `centre` where the composite differs from the camera image by more
/// than 40 in some channel: the virtual object drawn there.
int changed_pixels_near(const std::filesystem::path& frames, const std::string& frame, const Eigen::Vector2d& centre,
                        int radius) {
  const ColorImage camera = read_color(frames / (frame + "_color.png"));
  const ColorImage composite = read_color(frames / (frame + "_composite_mapped.png"));
  int changed = 0;
  for (int r = 0; r < camera.height(); ++r) {
    for (int c = 0; c < camera.width(); ++c) {
      if (std::hypot(c - centre.x(), r - centre.y()) > radius) continue;
      const Rgb8 a = camera(r, c), b = composite(r, c);
      changed += std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)}) > 40;
    }
  }
  return changed;
}

// The main job: `relight replay` with no arguments stands the shipped pebble on the desk of the
// embedded sample (its dominant support plane, at the free spot nearest the image centre), lit
// by the light estimated from the sample's own frames (it has no probe), and writes the
// composites and the video.
TEST(ReplayPlacement, TheMainJobStandsThePebbleOnTheSamplesDesk) {
  test::TempDir dir;
  const auto out = dir.path() / "main";
  const auto result = relight("replay --quiet --out " + out.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
  const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
  ASSERT_TRUE(report.contains("light_estimate")) << report.dump();
  EXPECT_NE(report["light_estimate"].value("chosen", "").find("has no light probe"), std::string::npos)
      << report["light_estimate"].dump();
  EXPECT_EQ(report["composite"]["rule"], "multiplicative");
  const auto placement = placement_of(out);
  EXPECT_EQ(placement["placement"], "support_plane");
  EXPECT_EQ(placement["frame"], 0);
  // The TUM world is z up: the desk's normal is the world's up.
  EXPECT_LT(degrees_between(vector_of(placement["up"]), Eigen::Vector3d::UnitZ()), 5.0) << placement.dump();
  // It is drawn where it stands: a 4 cm high pebble just above its foot point in frame 0.
  const Pose world_to_camera = first_pose(out / "camera_trajectory.txt").inverse();
  const PinholeIntrinsics sample_camera = PinholeIntrinsics::kinect_v1();  // what relight uses for TUM folders
  const Eigen::Vector3d centre = vector_of(placement["position_m"]) + 0.02 * vector_of(placement["up"]);
  const Eigen::Vector2d pixel = sample_camera.project(world_to_camera * centre);
  EXPECT_GT(changed_pixels_near(out / "frames", "000000", pixel, 25), 300) << pixel.transpose();
  // Geometry only on request.
  const auto geometry = dir.path() / "geometry";
  ASSERT_EQ(relight("replay --quiet --no-object --frames 0:1 --out " + geometry.string()).exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(geometry / "frames" / "000000_composite.png"));
  EXPECT_FALSE(nlohmann::json::parse(read_text_file(geometry / "report.json")).contains("placements"));
}

const std::filesystem::path& synthetic_sequence() { return cli_test::synthetic_sequence("--frames 2 --no-gt"); }

std::string render_into_synthetic(const std::string& placement, const std::filesystem::path& out) {
  return "replay --quiet --frames 0:1 --no-video --vpls 8 " + synthetic_sequence().string() + " --object " + kPebble +
         " " + placement + " --out " + out.string();
}

// --place-at: the pebble stands on the table top at the pixel that sees (-0.25, -0.15, 0.75)
// (the synthetic table's top is z = 0.75), within a centimetre, its up along the table's normal.
TEST(ReplayPlacement, PlaceAtStandsTheObjectOnTheSurfaceSeenAtThePixel) {
  test::TempDir dir;
  const Eigen::Vector3d target(-0.25, -0.15, 0.75);
  const Pose world_to_camera = first_pose(synthetic_sequence() / "groundtruth.txt").inverse();
  const PinholeIntrinsics intrinsics;  // relight synth's camera: 525, 319.5, 239.5, 640x480
  const Eigen::Vector2d pixel = intrinsics.project(world_to_camera * target);
  const auto out = dir.path() / "at";
  const auto result =
      relight(render_into_synthetic("--place-at " + std::to_string(pixel.x()) + "," + std::to_string(pixel.y()), out));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto placement = placement_of(out);
  EXPECT_EQ(placement["placement"], "pixel");
  EXPECT_LT((vector_of(placement["position_m"]) - target).norm(), 0.01) << placement.dump();
  EXPECT_LT(degrees_between(vector_of(placement["up"]), Eigen::Vector3d::UnitZ()), 3.0) << placement.dump();
  EXPECT_GT(changed_pixels_near(out / "frames", "000000",
                                intrinsics.project(world_to_camera * (target + Eigen::Vector3d(0, 0, 0.02))), 25),
            300);

  // --place-on-plane: on the table (the up-facing plane in view with a free spot nearest the
  // image centre; the floor is the larger one), inside its top.
  const auto plane_out = dir.path() / "plane";
  const auto on_plane = relight(render_into_synthetic("--place-on-plane 30", plane_out));
  ASSERT_EQ(on_plane.exit_code, 0) << on_plane.err;
  const auto on_table = placement_of(plane_out);
  const Eigen::Vector3d position = vector_of(on_table["position_m"]);
  EXPECT_NEAR(position.z(), 0.75, 0.01) << on_table.dump();
  EXPECT_LT(std::abs(position.x()), 0.6);
  EXPECT_LT(std::abs(position.y()), 0.4);
  EXPECT_EQ(on_table["yaw_from_camera_degrees"], 30.0);
  EXPECT_LT(degrees_between(vector_of(on_table["up"]), Eigen::Vector3d::UnitZ()), 3.0) << on_table.dump();
}

TEST(ReplayPlacement, PlacementsThatCannotBeResolvedAreOneLineErrors) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto outside = relight(render_into_synthetic("--place-at 700,20", out));
  expect_one_line_error(outside, 1);
  EXPECT_NE(outside.err.find("--place-at 700,20: pixel (700, 20) is outside the 640x480 image"), std::string::npos)
      << outside.err;
  expect_one_line_error(relight(render_into_synthetic("--place-at 10,x", out)), 1);
  expect_one_line_error(relight(render_into_synthetic("--place-at 10", out)), 1);
  expect_one_line_error(relight(render_into_synthetic("--place-on-plane 0,-1", out)), 1);
  const auto two = relight(render_into_synthetic("--place-at 10,10 --place-on-plane", out));
  expect_one_line_error(two, 1);
  EXPECT_NE(two.err.find("1 objects, 2 placements"), std::string::npos) << two.err;
  // A pixel that sees nothing and a frame without a support plane: a sample whose first depth
  // image sees only a patch of wall, facing the camera, in a corner.
  const auto sequence = dir.path() / "blank";
  std::filesystem::copy(kData / "tum_fr1_rpy", sequence, std::filesystem::copy_options::recursive);
  std::filesystem::path first_depth;
  for (const auto& entry : std::filesystem::directory_iterator(sequence / "depth"))
    if (first_depth.empty() || entry.path() < first_depth) first_depth = entry.path();
  DepthMap wall(640, 480, 0.f);
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 120; ++c) wall(r, c) = 2.f;
  write_depth_png(first_depth, wall, 5000.0);
  const auto lights = dir.path() / "lights.json";
  ASSERT_EQ(relight("lights " + (kData / "probes" / "grace_latlong.hdr").string() + " --n 4 --quiet --out " +
                    lights.string())
                .exit_code,
            0);
  const std::string on_blank = "replay --quiet --frames 0:1 --no-video " + sequence.string() + " --object " + kPebble +
                               " --lights " + lights.string() + " --out " + out.string();
  const auto no_surface = relight(on_blank + " --place-at 320,240");
  expect_one_line_error(no_surface, 1);
  EXPECT_NE(no_surface.err.find("--place-at 320,240: no surface at pixel (320, 240) of frame 0"), std::string::npos)
      << no_surface.err;
  const auto no_plane = relight(on_blank + " --place-on-plane");
  expect_one_line_error(no_plane, 1);
  EXPECT_NE(no_plane.err.find("--place-on-plane: no support plane in frame 0"), std::string::npos) << no_plane.err;
}

}  // namespace
}  // namespace relight::app
