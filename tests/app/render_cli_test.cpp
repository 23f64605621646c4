// `relight render-reference` and `relight models` as users run them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

const std::filesystem::path kData = RELIGHT_TEST_DATA;

/// A one-frame synthetic sequence, made once for the whole suite.
const std::filesystem::path& synthetic_sequence() { return cli_test::synthetic_sequence("--frames 1 --no-gt --noise none"); }

TEST(RenderReferenceCli, WritesLrvLrCompositeAndSummary) {
  test::TempDir dir;
  const auto out = dir.path() / "nested" / "ref.exr";
  const auto result = relight("render-reference --quiet --sequence " + synthetic_sequence().string() + " --object " +
                              (kData / "models" / "glossy_pebble.gltf").string() +
                              " --spp 2 --downsample 8 --out " + out.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const RadianceImage lrv = read_radiance(out);
  const RadianceImage lr = read_radiance(dir.path() / "nested" / "ref.Lr.exr");
  EXPECT_EQ(lrv.width(), 80);
  EXPECT_EQ(lrv.height(), 60);
  // The pebble on the table (default placement) changes some pixels, not most.
  int changed = 0;
  for (std::size_t i = 0; i < lrv.size(); ++i) changed += lrv.pixels()[i] == lr.pixels()[i] ? 0 : 1;
  EXPECT_GT(changed, 10);
  EXPECT_LT(changed, static_cast<int>(lrv.size()) / 2);
  EXPECT_EQ(read_color(dir.path() / "nested" / "ref.composite.png").width(), 80);
  const auto summary = nlohmann::json::parse(read_text_file(dir.path() / "nested" / "ref.json"));
  EXPECT_EQ(summary["samples_per_pixel"], 2);
  EXPECT_GT(summary["mrays_per_s"].get<double>(), 0.0);
  EXPECT_EQ(summary["caustic_light_paths"], 0);  // a Phong object: no light path is traced
}

// Glass focuses the room's lamps onto the table: with the same seed the camera paths are the same
// with and without the caustic light paths, so what those add is exactly the light through glass.
TEST(RenderReferenceCli, TheGlassPebbleFocusesTheLampsOntoTheTable) {
  test::TempDir dir;
  const std::string common = "render-reference --quiet --sequence " + synthetic_sequence().string() + " --object " +
                             (kData / "models" / "glass_pebble.gltf").string() +
                             " --spp 2 --downsample 8 --max-bounces 0";
  ASSERT_EQ(relight(common + " --out " + (dir.path() / "with.exr").string()).exit_code, 0);
  const auto without = relight(common + " --caustic-paths 0 --out " + (dir.path() / "without.exr").string());
  ASSERT_EQ(without.exit_code, 0) << without.err;
  EXPECT_GT(nlohmann::json::parse(read_text_file(dir.path() / "with.json"))["caustic_light_paths"].get<double>(), 0.0);
  EXPECT_EQ(nlohmann::json::parse(read_text_file(dir.path() / "without.json"))["caustic_light_paths"], 0);
  const RadianceImage with_rv = read_radiance(dir.path() / "with.exr"),
                      without_rv = read_radiance(dir.path() / "without.exr");
  const RadianceImage with_r = read_radiance(dir.path() / "with.Lr.exr"),
                      without_r = read_radiance(dir.path() / "without.Lr.exr");
  int brighter = 0;
  for (std::size_t i = 0; i < with_rv.size(); ++i) {
    ASSERT_EQ(with_r.pixels()[i], without_r.pixels()[i]);  // the glass is virtual: no caustic in L_r
    const float added = luminance(with_rv.pixels()[i]) - luminance(without_rv.pixels()[i]);
    ASSERT_GE(added, 0.f);
    brighter += added > 0.f;
  }
  EXPECT_GT(brighter, 5);
  EXPECT_LT(brighter, static_cast<int>(with_rv.size()) / 4);
}

// A real mirror (--real-object, as replay's) is part of both worlds: unlike the virtual pebble,
// it changes L_r too - the bottle itself and the light it reflects - while L_rv - L_r changes
// only where the pebble and the bottle meet (far fewer pixels). ref.json names it.
TEST(RenderReferenceCli, ARealMirrorBottleIsInBothWorlds) {
  test::TempDir dir;
  const std::string common = "render-reference --quiet --sequence " + synthetic_sequence().string() + " --object " +
                             (kData / "models" / "glossy_pebble.gltf").string() +
                             " --spp 2 --downsample 8 --max-bounces 0 --caustic-paths 0";
  ASSERT_EQ(relight(common + " --out " + (dir.path() / "plain.exr").string()).exit_code, 0);
  const auto result = relight(common + " --real-object " + (kData / "models" / "metal_bottle.gltf").string() +
                              " --real-place 0.12,-0.38,0.75 --out " + (dir.path() / "bottle.exr").string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto summary = nlohmann::json::parse(read_text_file(dir.path() / "bottle.json"));
  ASSERT_EQ(summary.at("real_objects").size(), 1u);
  EXPECT_EQ(summary["real_objects"][0]["model"], "metal_bottle.gltf");
  const RadianceImage plain_r = read_radiance(dir.path() / "plain.Lr.exr"),
                      bottle_r = read_radiance(dir.path() / "bottle.Lr.exr");
  const RadianceImage plain_rv = read_radiance(dir.path() / "plain.exr"),
                      bottle_rv = read_radiance(dir.path() / "bottle.exr");
  int real_changed = 0, delta_changed = 0;
  for (std::size_t i = 0; i < plain_r.size(); ++i) {
    real_changed += plain_r.pixels()[i] == bottle_r.pixels()[i] ? 0 : 1;
    const Float3 a = plain_rv.pixels()[i] - plain_r.pixels()[i], b = bottle_rv.pixels()[i] - bottle_r.pixels()[i];
    delta_changed += length(a - b) > 0.05f * std::max(length(a), 0.05f) ? 1 : 0;
  }
  std::cout << "L_r changed at " << real_changed << " pixels, L_rv - L_r at " << delta_changed << "\n";
  EXPECT_GT(real_changed, 5);
  EXPECT_LT(delta_changed, real_changed);
}

// The path tracer's composite takes the same operators as replay's: Reinhard's key from the
// traced L_rv itself (eq. 1 over its lit pixels), the highlight rolled off below the clamp's.
TEST(RenderReferenceCli, ReinhardTakesItsKeyFromTheTracedImage) {
  test::TempDir dir;
  const std::string common = "render-reference --quiet --sequence " + synthetic_sequence().string() + " --object " +
                             (kData / "models" / "glossy_pebble.gltf").string() + " --spp 2 --downsample 8";
  ASSERT_EQ(relight(common + " --out " + (dir.path() / "clamp.exr").string()).exit_code, 0);
  const auto result =
      relight(common + " --tone-map reinhard --tone-key 0.25 --out " + (dir.path() / "rh.exr").string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto tm = nlohmann::json::parse(read_text_file(dir.path() / "rh.json"))["tone_map"];
  EXPECT_EQ(tm["operator"], "reinhard") << tm.dump();
  const RadianceImage lrv = read_radiance(dir.path() / "rh.exr");
  double log_sum = 0.0, brightest = 0.0;
  int lit = 0;
  for (const Float3& p : lrv.pixels()) {
    const double y = luminance(p);
    if (!(y > 0.0)) continue;
    log_sum += std::log(1e-6 + y), ++lit;
    brightest = std::max<double>({brightest, p.x, p.y, p.z});
  }
  ASSERT_GT(lit, 100);
  // The summary's log average is over every second pixel of every second row: within a few %.
  EXPECT_NEAR(tm["log_average_luminance"].get<double>(), std::exp(log_sum / lit), 0.05 * std::exp(log_sum / lit));
  EXPECT_NEAR(tm["scale"].get<double>(), 0.25 / tm["log_average_luminance"].get<double>(), 1e-4);
  EXPECT_LE(tm["white"].get<double>(), brightest + 1e-4);
  EXPECT_EQ(nlohmann::json::parse(read_text_file(dir.path() / "clamp.json"))["tone_map"]["operator"], "exposure");
  const ColorImage reinhard = read_color(dir.path() / "rh.composite.png");
  int full = 0;
  for (const Rgb8& p : reinhard.pixels()) full += std::max({p.r, p.g, p.b}) == 255;
  EXPECT_LT(full, 8) << "at most the white's pixels reach 255";
}

TEST(RenderReferenceCli, VirtualLightBrightensOnlyLrv) {
  test::TempDir dir;
  const std::string common = "render-reference --quiet --sequence " + synthetic_sequence().string() + " --spp 1 --downsample 8";
  ASSERT_EQ(relight(common + " --out " + (dir.path() / "dark.exr").string()).exit_code, 0);
  const auto result = relight(common + " --virtual-light 0,0,1.5,2,1,0.5,0.2 --out " + (dir.path() / "lit.exr").string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const RadianceImage lit_lr = read_radiance(dir.path() / "lit.Lr.exr"), dark_lr = read_radiance(dir.path() / "dark.Lr.exr");
  EXPECT_TRUE(std::equal(lit_lr.pixels().begin(), lit_lr.pixels().end(), dark_lr.pixels().begin())) << "L_r ignores virtual lights";
  // Named: a range-for over read_radiance(...).pixels() would read the temporary after its end.
  const RadianceImage dark_image = read_radiance(dir.path() / "dark.exr");
  const RadianceImage lit_image = read_radiance(dir.path() / "lit.exr");
  double dark = 0.0, lit = 0.0;
  for (const Float3& p : dark_image.pixels()) dark += p.x;
  for (const Float3& p : lit_image.pixels()) lit += p.x;
  EXPECT_GT(lit, 1.1 * dark);
  expect_one_line_error(relight(common + " --virtual-light 0,0,1.5 --out " + (dir.path() / "x.exr").string()), 1);
}

TEST(RenderReferenceCli, BadInputGivesOneLineErrors) {
  test::TempDir dir;
  const std::string seq = " --sequence " + synthetic_sequence().string();
  const std::string out = " --out " + (dir.path() / "ref.exr").string();
  expect_one_line_error(relight("render-reference --sequence /no/such/folder" + out), 1);
  expect_one_line_error(relight("render-reference" + seq + " --out " + (dir.path() / "ref.png").string()), 1);
  expect_one_line_error(relight("render-reference" + seq + " --frame 7" + out), 1);
  expect_one_line_error(relight("render-reference" + seq + " --object /no/such/model.glb" + out), 1);
  expect_one_line_error(relight("render-reference" + seq + " --object " + (kData / "models" / "matte_box.obj").string() +
                                " --place 1,2" + out),
                        1);
  expect_one_line_error(
      relight("render-reference" + seq + " --real-object " + (kData / "models" / "metal_bottle.gltf").string() + out),
      1);  // no --real-place
  // A recorded sequence has no lights of its own.
  expect_one_line_error(relight("render-reference --sequence " + (kData / "tum_fr1_rpy").string() + out), 1);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "ref.exr"));
}

TEST(ModelsCli, RegeneratesTheShippedModelsByteForByte) {
  test::TempDir dir;
  ASSERT_EQ(relight("models --out " + dir.path().string()).exit_code, 0);
  for (const char* file :
       {"glossy_pebble.gltf", "glass_pebble.gltf", "metal_bottle.gltf", "matte_box.obj", "matte_box.mtl"})
    EXPECT_EQ(read_text_file(dir.path() / file), read_text_file(kData / "models" / file)) << file;
}

}  // namespace
}  // namespace relight::app
