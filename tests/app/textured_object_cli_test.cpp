// `relight replay` with a textured glTF object (data/models/box_textured.gltf, the Cesium logo on
// a cube): the composite shows the texture on the object, an untextured copy of the same model
// shows flat faces, the logo as a normal texture bends the shading and as a metallic-roughness
// texture varies the material, and a model whose texture cannot be decoded is one error line.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <utility>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

const std::filesystem::path kBox = std::filesystem::path(RELIGHT_TEST_DATA) / "models" / "box_textured.gltf";

const std::filesystem::path& sequence() {
  return cli_test::synthetic_sequence("--frames 2 --size 320x240 --trajectory static");
}

test::CommandResult replay(const std::filesystem::path& model, const std::filesystem::path& out) {
  // The 1 m box, centred on its origin, scaled to 12 cm and lifted to stand on the table.
  return relight("replay --quiet " + sequence().string() + " --object " + model.string() +
                 " --place 0.35,-0.2,0.81,30,0.12 --camera-artefacts none --colormap none --no-video --buffers --out " +
                 out.string());
}

/// Mean absolute green difference between horizontal neighbours that are both fully covered by
/// the object: the texture's detail (shading alone changes little from pixel to pixel).
double covered_detail(const std::filesystem::path& run, int& pixels) {
  const ColorImage composite = read_color(run / "frames" / "000001_composite.png");
  const ColorImage coverage = read_color(run / "frames" / "000001_virtual_coverage.png");
  double sum = 0;
  pixels = 0;
  for (int r = 1; r < composite.height() - 1; ++r)
    for (int c = 1; c < composite.width() - 1; ++c) {
      bool inside = true;
      for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 2; ++j)
          inside = inside && coverage.in_bounds(r + i, c + j) && coverage(r + i, c + j).r == 255;
      if (!inside) continue;
      sum += std::abs(double(composite(r, c + 1).g) - double(composite(r, c).g));
      ++pixels;
    }
  return pixels > 0 ? sum / pixels : 0.0;
}

/// The box with its base-colour reference renamed to a key glTF does not know (flat faces).
std::string untextured_box() {
  std::string out = read_text_file(kBox);
  const std::size_t reference = out.find("\"baseColorTexture\"");
  EXPECT_NE(reference, std::string::npos);
  if (reference != std::string::npos)
    out.replace(reference, std::string("\"baseColorTexture\"").size(), "\"unusedTexture\"");
  return out;
}

/// covered_detail() of `model`'s replay and of the flat box's, each run into `dir`; nullopt
/// (with a test failure) when a run fails or the object covers too little of the frame.
std::optional<std::pair<double, double>> detail_against_flat(const test::TempDir& dir,
                                                             const std::filesystem::path& model, const char* what) {
  write_file_atomically(dir.path() / "flat.gltf", untextured_box());
  const auto run = replay(model, dir.path() / "model");
  const auto flat_run = replay(dir.path() / "flat.gltf", dir.path() / "flat");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(flat_run.exit_code, 0) << flat_run.err;
  if (run.exit_code != 0 || flat_run.exit_code != 0) return std::nullopt;
  int pixels = 0, flat_pixels = 0;
  const double detail = covered_detail(dir.path() / "model", pixels);
  const double flat = covered_detail(dir.path() / "flat", flat_pixels);
  std::printf("detail inside the box: %s %.2f (%d px), untextured %.2f (%d px)\n", what, detail, pixels, flat,
              flat_pixels);
  EXPECT_GT(pixels, 200) << "the box covers part of the frame";
  if (pixels <= 200) return std::nullopt;
  return std::pair{detail, flat};
}

TEST(TexturedObjectCli, TheCompositeShowsTheModelsTexture) {
  test::TempDir dir;
  const auto detail = detail_against_flat(dir, kBox, "textured");
  ASSERT_TRUE(detail);
  EXPECT_GT(detail->first, 2.5 * detail->second + 0.5);  // measured 10.3 against 2.9
}

// The flat box with the logo as its normal texture: the bent normals shade the faces unevenly.
TEST(TexturedObjectCli, ANormalTextureBendsTheShading) {
  test::TempDir dir;
  std::string bumped = untextured_box();
  const std::size_t material = bumped.find("\"pbrMetallicRoughness\"");
  ASSERT_NE(material, std::string::npos);
  bumped.insert(material, "\"normalTexture\": {\"index\": 0, \"scale\": 1.0}, ");
  write_file_atomically(dir.path() / "bumped.gltf", bumped);
  const auto detail = detail_against_flat(dir, dir.path() / "bumped.gltf", "normal-mapped");
  ASSERT_TRUE(detail);
  EXPECT_GT(detail->first, 2.0 * detail->second + 0.5);  // measured 17.3 against 2.9
}

// The flat box with the logo as its metallic-roughness texture (the logo's blue metallic, its
// green rough): k_d, k_s and n change across the faces.
TEST(TexturedObjectCli, AMetallicRoughnessTextureVariesTheMaterial) {
  test::TempDir dir;
  std::string varied = untextured_box();
  const std::size_t pbr = varied.find("\"pbrMetallicRoughness\": {");
  ASSERT_NE(pbr, std::string::npos);
  varied.insert(pbr + std::string("\"pbrMetallicRoughness\": {").size(),
                "\"metallicRoughnessTexture\": {\"index\": 0}, ");
  // metallicFactor 0 would zero the texture's metallic: let the texture decide.
  const std::size_t factor = varied.find("\"metallicFactor\": 0.0");
  ASSERT_NE(factor, std::string::npos);
  varied.replace(factor, std::string("\"metallicFactor\": 0.0").size(), "\"metallicFactor\": 1.0");
  write_file_atomically(dir.path() / "varied.gltf", varied);
  const auto detail = detail_against_flat(dir, dir.path() / "varied.gltf", "metallic-roughness");
  ASSERT_TRUE(detail);
  EXPECT_GT(detail->first, 2.0 * detail->second + 0.5);
}

TEST(TexturedObjectCli, AnUndecodableTextureIsOneErrorLine) {
  test::TempDir dir;
  std::string broken = read_text_file(kBox);
  const std::size_t data = broken.find("data:image/png;base64,");
  ASSERT_NE(data, std::string::npos);
  const std::size_t payload = data + std::string("data:image/png;base64,").size();
  broken.replace(payload, broken.find('"', payload) - payload, "AAAAAAAAAAAA");  // 9 zero bytes
  write_file_atomically(dir.path() / "broken.gltf", broken);
  const auto result = replay(dir.path() / "broken.gltf", dir.path() / "out");
  expect_one_line_error(result, 1);
  EXPECT_NE(result.err.find("image 0"), std::string::npos) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "report.json"));
}

}  // namespace
}  // namespace relight::app
