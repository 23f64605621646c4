// `relight replay` with virtual content: composites per frame, composite.mp4, the L_rv/L_r
// buffers on request, and one-line errors for what it cannot render.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/colormap/color_space.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_dispatches_on_the_device;
using cli_test::expect_one_line_error;
using cli_test::relight;

const std::filesystem::path kData = RELIGHT_TEST_DATA;

const std::filesystem::path& two_frame_sequence() { return cli_test::synthetic_sequence("--frames 2 --no-gt"); }

TEST(ReplayRenderCli, WritesCompositesVideoAndBuffers) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto result = relight("replay --quiet " + two_frame_sequence().string() + " --object " +
                              (kData / "models" / "glossy_pebble.gltf").string() + " --vpls 32 --buffers --out " +
                              out.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* frame : {"000000", "000001"}) {
    const ColorImage camera = read_color(out / "frames" / (std::string(frame) + "_color.png"));
    const ColorImage composite = read_color(out / "frames" / (std::string(frame) + "_composite.png"));
    ASSERT_EQ(composite.width(), camera.width());
    int changed = 0;
    for (std::size_t i = 0; i < camera.size(); ++i) changed += camera.pixels()[i] == composite.pixels()[i] ? 0 : 1;
    EXPECT_GT(changed, 200) << "the pebble and its shadow";
    EXPECT_LT(changed, static_cast<int>(camera.size()) / 4);
    // The colour-mapped composite (--colormap stats by default) changes the same pixels.
    const ColorImage mapped = read_color(out / "frames" / (std::string(frame) + "_composite_mapped.png"));
    ASSERT_EQ(mapped.width(), camera.width());
    int mapped_changed = 0, largest_elsewhere = 0;
    for (std::size_t i = 0; i < camera.size(); ++i) {
      const Rgb8 a = camera.pixels()[i], b = mapped.pixels()[i];
      mapped_changed += a != b ? 1 : 0;
      if (a == composite.pixels()[i]) {
        largest_elsewhere = std::max({largest_elsewhere, std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
      }
    }
    EXPECT_GT(mapped_changed, 200);
    // Where the unmapped composite rounds back to the camera pixel, the mapping may scale the tiny
    // difference across a rounding step, but it adds nothing visible.
    EXPECT_LE(largest_elsewhere, 4);  // 3 measured
    const RadianceImage lrv = read_radiance(out / "frames" / (std::string(frame) + "_L_rv.exr"));
    EXPECT_EQ(lrv.width(), camera.width());
    const RadianceImage delta = read_radiance(out / "frames" / (std::string(frame) + "_delta_L.exr"));
    int nonzero = 0;
    for (const Float3& d : delta.pixels()) nonzero += d == Float3{} ? 0 : 1;
    EXPECT_GT(nonzero, 200) << "delta_L is non-zero where the pebble changes the picture";
  }
  ASSERT_TRUE(std::filesystem::exists(out / "composite.mp4"));
  EXPECT_GT(std::filesystem::file_size(out / "composite.mp4"), 1000u);
  EXPECT_FALSE(std::filesystem::exists(out / "composite.partial.mp4"));
  const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
  EXPECT_NE(report.dump().find("\"dir\""), std::string::npos) << "the DIR stage is timed";
  // And where its time goes: every frame's steps, the rasterising ones on the device.
  const auto& steps = report["dir_steps"];
  ASSERT_TRUE(steps.is_object()) << report.dump();
  EXPECT_EQ(steps["frames"], report["frames"]);
  // On a CPU device (lavapipe) the shading runs on the CPU (DirBackend::Auto).
  const bool cpu_device = report["compute"].get<std::string>().find("llvmpipe") != std::string::npos;
  EXPECT_EQ(steps["shading_on"], cpu_device ? "cpu" : "device");
  for (const char* step : {"gbuffer", "shadow_maps", "ism", "shading"})
    EXPECT_GT(steps["median_ms"][step].get<double>(), 0.0) << step;
}

// Also runs two VPL bounces by the point-cone method, which this scene exercises nowhere else.
TEST(ReplayRenderCli, ColormapNoneWritesOnlyTheUnmappedComposite) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto result = relight("replay --quiet --frames 1 --no-video --colormap none " + two_frame_sequence().string() +
                              " --object " + (kData / "models" / "glossy_pebble.gltf").string() +
                              " --vpls 16 --vpl-bounces 2 --bounce-method cone --out " + out.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000000_composite.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "frames" / "000000_composite_mapped.png"));
  EXPECT_EQ(read_text_file(out / "report.json").find("colormap"), std::string::npos);
}

// The multiple-bounce light source (--bounce-method previous-frame, Knecht 2010 §4.3) through
// replay: the first frame has nothing to continue and renders exactly what one bounce renders;
// from the next on, a quarter of the samples continue the previous frame's VPLs (report.json's
// vpls says how many of each bounce). That they carry the second bounce's energy is
// Vpls.PreviousFrameBouncesCarryTheEnergyOfTheRayTracedOnes: in this room the second bounce adds
// about 1 % to the mean L_r, less than changing the VPL count moves it.
TEST(ReplayRenderCli, PreviousFrameBouncesStartOnTheSecondFrame) {
  test::TempDir dir;
  const auto& sequence = cli_test::synthetic_sequence("--frames 3 --size 320x240 --trajectory static --no-gt");
  struct Run {
    std::vector<double> mean_real_light;  // frames 0 and 2
    nlohmann::json report;
  };
  const auto run = [&](const std::string& name, const std::string& options) {
    const auto out = dir.path() / name;
    const auto result = relight("replay --quiet --no-video --buffers " + sequence.string() + " --object " +
                                (kData / "models" / "glossy_pebble.gltf").string() + " --vpls 256 " + options +
                                " --out " + out.string());
    EXPECT_EQ(result.exit_code, 0) << result.err;
    Run r;
    if (result.exit_code != 0) return r;
    for (const char* frame : {"000000", "000002"}) {
      const RadianceImage lr = read_radiance(out / "frames" / (std::string(frame) + "_L_r.exr"));
      double sum = 0.0;
      for (const Float3& v : lr.pixels()) sum += static_cast<double>(v.x) + v.y + v.z;
      r.mean_real_light.push_back(sum / static_cast<double>(lr.size()));
    }
    r.report = nlohmann::json::parse(read_text_file(out / "report.json"));
    return r;
  };
  const Run one = run("one", "--vpl-bounces 1");
  const Run previous = run("previous", "--vpl-bounces 2 --bounce-method previous-frame");
  ASSERT_EQ(one.mean_real_light.size(), 2u);
  ASSERT_EQ(previous.mean_real_light.size(), 2u);
  const auto& vpls = previous.report["vpls"];
  EXPECT_EQ(vpls["bounce_method"], "previous-frame") << vpls.dump();
  EXPECT_EQ(vpls["first_frame_later_bounces"], 0);
  EXPECT_DOUBLE_EQ(vpls["bounce_share"].get<double>(), 0.25);
  // Frames 1 and 2 continue 64 samples each; as with ray-traced bounces, most leave the
  // reconstructed part of the room (measured: 20.5 of 64 land, rays 46 of 214).
  const double continued_per_frame = vpls["mean_per_frame"]["bounce_2"].get<double>() * 3.0 / 2.0;
  EXPECT_GT(continued_per_frame, 0.15 * 64) << vpls.dump();
  EXPECT_LE(continued_per_frame, 64.0) << vpls.dump();
  EXPECT_FALSE(vpls["mean_per_frame"].contains("bounce_3"));
  EXPECT_EQ(one.report["vpls"]["bounce_method"], "rays");
  EXPECT_FALSE(one.report["vpls"]["mean_per_frame"].contains("bounce_2"));
  EXPECT_DOUBLE_EQ(previous.mean_real_light[0], one.mean_real_light[0]) << "the first frame renders one bounce";
  EXPECT_NE(previous.mean_real_light[1], one.mean_real_light[1]);
  std::printf("mean L_r, frame 2: one bounce %.4f, previous-frame bounces %.4f\n", one.mean_real_light[1],
              previous.mean_real_light[1]);
  expect_one_line_error(
      relight("replay --quiet " + sequence.string() + " --bounce-share 1.5 --out " + (dir.path() / "bad").string()), 2);
}

// A virtual spot light lights its footprint on the table; its first VPLs from the rasterised
// RSMs (--vpl-source rsm) give the picture the traced ones give. Measured (64 light samples shared
// equally by the 9 lights): a footprint of 26430 pixels; 8092 pixels differ between the two
// sources, those in the footprint by 0.57 levels on average (26383, 8441 and 0.77 before the
// edge-aware interleave merge).
TEST(ReplayRenderCli, VirtualSpotLightWithRsmVplsLightsItsFootprint) {
  test::TempDir dir;
  ColorImage composites[2];
  const char* sources[2] = {"rays", "rsm"};
  for (int s = 0; s < 2; ++s) {
    const auto out = dir.path() / sources[s];
    const auto result = relight("replay --quiet --frames 1 --no-video --colormap none " + two_frame_sequence().string() +
                                " --virtual-spot 0.35,-0.2,1.8,0.35,-0.2,0.75,20,3 --vpls 64 --vpl-budget equal --vpl-source " +
                                sources[s] + " --out " + out.string());
    ASSERT_EQ(result.exit_code, 0) << result.err;
    composites[s] = read_color(out / "frames" / "000000_composite.png");
  }
  // The RSMs are rasterised on the device: the VPL stage says so and reports their GPU time.
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "rsm" / "report.json"));
  expect_dispatches_on_the_device(report, "vpls");
  const ColorImage camera = read_color(dir.path() / "rsm" / "frames" / "000000_color.png");
  const auto sum = [](Rgb8 c) { return c.r + c.g + c.b; };
  int lit = 0, differ = 0;
  double difference = 0.0;
  for (std::size_t i = 0; i < camera.size(); ++i) {
    differ += composites[0].pixels()[i] != composites[1].pixels()[i] ? 1 : 0;
    if (sum(composites[1].pixels()[i]) - sum(camera.pixels()[i]) <= 30) continue;
    ++lit;
    const Rgb8 a = composites[0].pixels()[i], b = composites[1].pixels()[i];
    difference += (std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b)) / 3.0;
  }
  std::printf("spot footprint: %d pixels; %d pixels differ between the sources, in the footprint by %.2f levels on "
              "average\n", lit, differ, difference / std::max(lit, 1));
  EXPECT_GT(differ, 1000) << "the spot's VPLs come from elsewhere with --vpl-source rsm";
  EXPECT_GT(lit, 10000);
  EXPECT_LT(lit, static_cast<int>(camera.size()) / 2);
  EXPECT_LT(difference / lit, 2.0);
}

// The real-only render L_r against the camera image it stands for: the chromaticity of L_r and of
// the linearised camera colour on every lit real pixel. Shading real surfaces with each pixel's
// own k_d estimate (--real-albedo pixel, the default) makes L_r carry the camera's colours;
// with the material clusters' k_d it carries the clusters'. Measured (median chromaticity
// error, L1): pixel albedo 0.0091, cluster albedo 0.0473 (before the edge-aware interleave merge:
// 0.0089 and 0.0453; 0.0072 without the 5 x 5 smoothing).
TEST(ReplayRenderCli, RealOnlyRenderCarriesTheCamerasColoursWithPerPixelAlbedo) {
  test::TempDir dir;
  double median_error[2] = {0, 0};
  const char* albedo[2] = {"pixel", "cluster"};
  for (int a = 0; a < 2; ++a) {
    const auto out = dir.path() / albedo[a];
    const auto result = relight("replay --quiet --frames 1 --no-video --colormap none --buffers --vpls 16 " +
                                two_frame_sequence().string() + " --object " +
                                (kData / "models" / "glossy_pebble.gltf").string() + " --real-albedo " + albedo[a] +
                                " --out " + out.string());
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const ColorImage camera = read_color(out / "frames" / "000000_color.png");
    const RadianceImage real = read_radiance(out / "frames" / "000000_L_r.exr");
    ASSERT_TRUE(real.same_shape(camera));
    std::vector<double> errors;
    for (std::size_t i = 0; i < camera.size(); ++i) {
      const Rgb8 c = camera.pixels()[i];
      const Float3 r = real.pixels()[i];
      const double cam[3] = {colormap::srgb8_to_linear(c.r), colormap::srgb8_to_linear(c.g), colormap::srgb8_to_linear(c.b)};
      const double sum_cam = cam[0] + cam[1] + cam[2], sum_r = double(r.x) + r.y + r.z;
      if (sum_cam < 0.15 || sum_r < 0.15 || std::max({c.r, c.g, c.b}) >= 250) continue;  // dark or clipped
      errors.push_back(std::abs(cam[0] / sum_cam - r.x / sum_r) + std::abs(cam[1] / sum_cam - r.y / sum_r) +
                       std::abs(cam[2] / sum_cam - r.z / sum_r));
    }
    ASSERT_GT(errors.size(), camera.size() / 4);
    std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
    median_error[a] = errors[errors.size() / 2];
  }
  std::printf("median chromaticity error of L_r against the camera: pixel albedo %.4f, cluster albedo %.4f\n",
              median_error[0], median_error[1]);
  EXPECT_LT(median_error[0], 0.03);
  EXPECT_LT(median_error[0], 0.5 * median_error[1]);
}

// A real mirror given as a model (--real-object; the aluminium bottle beside the pebble): the
// pebble is seen in it, so DeltaL changes there and in the pebble's light around the bottle, and
// nowhere else - the bottle's own light, in both worlds, cancels. report.json names it.
TEST(ReplayRenderCli, ARealMirrorModelShowsThePebbleAndChangesNothingElse) {
  test::TempDir dir;
  const std::string common = "replay --quiet " + two_frame_sequence().string() + " --object " +
                             (kData / "models" / "glossy_pebble.gltf").string() + " --vpls 32 --buffers --out ";
  const auto plain = dir.path() / "plain", mirrored = dir.path() / "mirrored";
  ASSERT_EQ(relight(common + plain.string()).exit_code, 0);
  const auto result = relight(common + mirrored.string() + " --real-object " +
                              (kData / "models" / "metal_bottle.gltf").string() + " --real-place 0.12,-0.38,0.75");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(read_text_file(mirrored / "report.json"));
  ASSERT_EQ(report.at("real_objects").size(), 1u);
  EXPECT_EQ(report["real_objects"][0]["model"], "metal_bottle.gltf");
  for (const char* frame : {"000000", "000001"}) {
    const RadianceImage a = read_radiance(plain / "frames" / (std::string(frame) + "_delta_L.exr"));
    const RadianceImage b = read_radiance(mirrored / "frames" / (std::string(frame) + "_delta_L.exr"));
    ASSERT_TRUE(a.same_shape(b));
    // Changes below 0.01 are everywhere: the VPLs land elsewhere once the bottle stands in the
    // room, and the pebble's own indirect light reaches the whole room.
    int changed = 0, strongly = 0;
    Eigen::AlignedBox2i where;
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) {
        const Float3 d = a(y, x) - b(y, x);
        const float m = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
        changed += m > 0.01f ? 1 : 0;
        if (m <= 0.1f) continue;
        ++strongly;
        where.extend(Eigen::Vector2i(x, y));
      }
    std::cout << frame << ": DeltaL changed by > 0.01 at " << changed << " pixels, by > 0.1 at " << strongly
              << " within columns " << where.min().x() << ".." << where.max().x() << ", rows " << where.min().y()
              << ".." << where.max().y() << "\n";
    EXPECT_GT(strongly, 20) << "the pebble seen in the bottle";
    EXPECT_LT(where.sizes().x(), 200);  // the bottle and the pebble beside it, 140 x 70 measured
    EXPECT_LT(where.sizes().y(), 120);
    EXPECT_LT(changed, static_cast<int>(a.size()) / 50);
  }
}

TEST(ReplayRenderCli, WithoutVirtualContentNothingIsRendered) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  ASSERT_EQ(relight("replay --quiet --frames 1 " + two_frame_sequence().string() + " --out " + out.string()).exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(out / "frames" / "000000_composite.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "composite.mp4"));
}

TEST(ReplayRenderCli, BadRenderInputGivesOneLineErrors) {
  test::TempDir dir;
  const std::string out = " --out " + (dir.path() / "out").string();
  const std::string seq = " " + two_frame_sequence().string();
  const std::string pebble = " --object " + (kData / "models" / "glossy_pebble.gltf").string();
  expect_one_line_error(relight("replay" + seq + " --object /no/such/model.glb" + out), 1);
  expect_one_line_error(relight("replay" + seq + pebble + pebble + " --place 0,0,1" + out), 1);  // 2 objects, 1 place
  expect_one_line_error(relight("replay" + seq + " --virtual-light 1,2,x,4" + out), 1);
  expect_one_line_error(relight("replay" + seq + " --virtual-spot 0,0,1,0,0,1,30,2" + out), 1);  // aimed at itself
  expect_one_line_error(relight("replay" + seq + " --virtual-spot 0,0,1,0,0,0,95,2" + out), 1);  // wider than 90
  expect_one_line_error(relight("replay" + seq + " --virtual-spot 0,0,1,0,0,0,30" + out), 1);    // no intensity
  expect_one_line_error(relight("replay" + seq + pebble + " --vpl-source photons" + out), 2);
  expect_one_line_error(relight("replay" + seq + pebble + " --real-albedo texture" + out), 2);
  expect_one_line_error(relight("replay" + seq + pebble + " --colormap vivid" + out), 2);  // a usage error
  expect_one_line_error(relight("replay" + seq + pebble + " --colormap sample --colormap-model cubic" + out), 2);
  expect_one_line_error(relight("replay" + seq + pebble + " --vpl-budget most" + out), 2);
  expect_one_line_error(relight("replay" + seq + pebble + " --vpl-budget weights --vpl-weights 1,-2" + out), 2);
  expect_one_line_error(relight("replay" + seq + pebble + " --vpl-bounces 0" + out), 2);
  expect_one_line_error(relight("replay" + seq + pebble + " --bounce-method photons" + out), 2);
  const std::string bottle = " --real-object " + (kData / "models" / "metal_bottle.gltf").string();
  expect_one_line_error(relight("replay" + seq + pebble + bottle + out), 1);                 // no --real-place
  expect_one_line_error(relight("replay" + seq + bottle + " --real-place 0,0,1" + out), 1);  // nothing virtual
  expect_one_line_error(relight("replay" + seq + pebble + bottle + " --real-place 0,0" + out), 1);
  expect_one_line_error(relight("replay" + seq + pebble + " --real-object /no/such.glb --real-place 0,0,1" + out), 1);
  // A recorded sequence needs a placement (its lights, without a probe, are estimated: cli_test.cpp).
  expect_one_line_error(relight("replay " + (kData / "tum_fr1_rpy").string() + pebble + out), 1);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "composite.mp4"));
}

}  // namespace
}  // namespace relight::app

namespace relight::app {
namespace {

// With every stage that can on the Vulkan device, the main job (the pebble on the sample's desk)
// allocates device memory only in its first two frames: stages keep their device buffers, the
// graph keeps history on the device, and buffers whose size changes every frame (the
// reconstruction mesh, ISM points, K-means points) grow with headroom. report.json says so.
TEST(ReplayRenderCli, ASteadyVulkanRunAllocatesNoDeviceMemory) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto result = relight("replay --quiet --backend vulkan --loop 3 --no-video --no-frames --out " + out.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
  ASSERT_TRUE(report.contains("device_memory")) << report.dump(2);
  EXPECT_EQ(report["frames"].get<int>(), 12);
  EXPECT_GT(report["device_memory"]["allocations"].get<int>(), 10);
  EXPECT_EQ(report["device_memory"]["allocations_after_frame_2"].get<int>(), 0);
  // Every stage that dispatches on the device says so and reports its GPU time (lavapipe has
  // timestamps); where its buffers live is its own row (the per-pixel ones on the device).
  for (const char* name :
       {"depth_box_filter", "normals_raw_depth", "kmeans", "specular_fit", "dir", "colormap_statistics"}) {
    const nlohmann::json stage = expect_dispatches_on_the_device(report, name);
    const bool host_buffers =
        std::string(name) == "kmeans" || std::string(name) == "specular_fit" || std::string(name) == "dir";
    EXPECT_EQ(stage.value("buffers", ""), host_buffers ? "host" : "device") << name;
  }
  // Method 2 on the device: warp and merge keep depth and weight as device history, and the
  // plain normals read the merged depth where it already is.
  const auto method2 = dir.path() / "method2";
  ASSERT_EQ(relight("replay --quiet --backend vulkan --no-object --geometry method2 --method2-normals plain --loop 3 "
                    "--no-video --no-frames --out " +
                    method2.string())
                .exit_code,
            0);
  const auto method2_report = nlohmann::json::parse(read_text_file(method2 / "report.json"));
  EXPECT_EQ(method2_report["device_memory"]["allocations_after_frame_2"].get<int>(), 0);
  // Second bounces by the point-cone search on the device: its point, query and hit buffers are
  // kept too (grown with headroom, so the first frames may still grow them: a run three times as
  // long allocates nothing more), and the VPL stage reports the searches' GPU time.
  int cone_allocations[2] = {0, 0};
  nlohmann::json cone_report;
  for (int run = 0; run < 2; ++run) {
    const auto cone = dir.path() / ("cone" + std::to_string(run));
    ASSERT_EQ(relight("replay --quiet --backend vulkan --vpl-bounces 2 --bounce-method cone --loop " +
                      std::to_string(1 + 2 * run) + " --no-video --no-frames --out " + cone.string())
                  .exit_code,
              0);
    cone_report = nlohmann::json::parse(read_text_file(cone / "report.json"));
    cone_allocations[run] = cone_report["device_memory"]["allocations"].get<int>();
  }
  EXPECT_EQ(cone_report["frames"].get<int>(), 12);
  EXPECT_EQ(cone_allocations[1], cone_allocations[0]) << "4 frames against 12";
  expect_dispatches_on_the_device(cone_report, "vpls");
}

}  // namespace
}  // namespace relight::app
