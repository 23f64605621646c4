// Base-colour textures: sampling, mip levels and wrap modes (texture.h), glTF loading of textured
// materials and its errors (model_io.h), and the renderers shading with them: the CPU DIR's
// direct light and the path tracer against the closed form of a textured plane under a sun.
#include "relight/render/scene/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <utility>

#include "glb_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/render/dir/dir.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/model_io.h"
#include "temp_dir.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

ColorImage image_of(int width, int height, const std::vector<Rgb8>& pixels) {
  ColorImage out(width, height);
  std::copy(pixels.begin(), pixels.end(), out.pixels().begin());
  return out;
}

Eigen::Vector3f linear(const Rgb8& c) { return {srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b)}; }

const Rgb8 kRed{200, 30, 20}, kGreen{40, 180, 60}, kBlue{20, 40, 220}, kWhite{250, 250, 250};

TEST(Texture, SrgbCurveRoundTripsEveryValue) {
  EXPECT_FLOAT_EQ(srgb_to_linear(0), 0.f);
  EXPECT_FLOAT_EQ(srgb_to_linear(255), 1.f);
  EXPECT_NEAR(srgb_to_linear(188), 0.5029f, 1e-4f);  // the curve, not a 2.2 power (0.5025)
  for (int v = 0; v < 256; ++v) EXPECT_EQ(linear_to_srgb(srgb_to_linear(static_cast<std::uint8_t>(v))), v);
}

TEST(Texture, SamplesTexelCentresAndFiltersInLinearLight) {
  const Texture texture("2x2", image_of(2, 2, {kRed, kGreen, kBlue, kWhite}));
  EXPECT_LT((texture.sample(0.25f, 0.25f) - linear(kRed)).norm(), 1e-6f) << "top-left texel centre";
  EXPECT_LT((texture.sample(0.75f, 0.75f) - linear(kWhite)).norm(), 1e-6f);
  // Half way between two texel centres: the mean of their linear values, not of the encoded ones.
  const Eigen::Vector3f between = texture.sample(0.5f, 0.25f);
  EXPECT_LT((between - 0.5f * (linear(kRed) + linear(kGreen))).norm(), 1e-6f);
}

TEST(Texture, LinearTexturesHoldDataNotColours) {
  // Metallic-roughness texels are values / 255, filtered and mip-mapped as they are.
  const Rgb8 a{0, 51, 255}, b{0, 153, 0};
  const Texture texture("data", image_of(2, 1, {a, b}), TextureWrap::ClampToEdge, TextureWrap::ClampToEdge,
                        TextureEncoding::Linear);
  EXPECT_EQ(texture.encoding(), TextureEncoding::Linear);
  EXPECT_LT((texture.sample(0.25f, 0.5f) - Eigen::Vector3f(0.f, 0.2f, 1.f)).norm(), 1e-6f);
  EXPECT_LT((texture.sample(0.5f, 0.5f) - Eigen::Vector3f(0.f, 0.4f, 0.5f)).norm(), 1e-6f);
  ASSERT_EQ(texture.levels(), 2);
  EXPECT_EQ(texture.texels()[texture.level_offset(1)], 0u | (102u << 8) | (128u << 16)) << "the mean of the values";
  // The same bytes as colours decode through the sRGB curve.
  const Texture colour("colour", image_of(2, 1, {a, b}));
  EXPECT_NEAR(colour.sample(0.25f, 0.5f).y(), srgb_to_linear(51), 1e-6f);
}

// KHR_texture_transform: the README's example "only the lower left quadrant of the source image,
// rotated clockwise 90 degrees" (offset (0, 1), rotation pi/2, scale 0.5).
TEST(Texture, TheGltfTextureTransformMapsCoordinatesFirst) {
  ColorImage quadrants(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) quadrants(y, x) = y < 2 ? (x < 2 ? kRed : kGreen) : (x < 2 ? kBlue : kWhite);
  const UvTransform transform = UvTransform::gltf({0.f, 1.f}, std::numbers::pi_v<float> / 2.f, {0.5f, 0.5f});
  const Texture texture("quadrants", quadrants, TextureWrap::ClampToEdge, TextureWrap::ClampToEdge,
                        TextureEncoding::Srgb, transform);
  for (const auto& [u, v] :
       {std::pair{0.1f, 0.1f}, std::pair{0.5f, 0.5f}, std::pair{0.7f, 0.2f}, std::pair{0.3f, 0.7f}})
    EXPECT_LT((texture.sample(u, v) - linear(kBlue)).norm(), 1e-6f) << "lower left (blue) at " << u << "," << v;
  // Rotated clockwise as the image shows it: the quadrant's top edge (v' = 0.5) lands on the
  // coordinates' right edge (u = 1), its left edge (u' = 0) on the top (v = 0).
  EXPECT_LT((transform.apply({1.f, 0.3f}) - Eigen::Vector2f(0.15f, 0.5f)).norm(), 1e-6f);
  EXPECT_LT((transform.apply({0.3f, 0.f}) - Eigen::Vector2f(0.f, 0.85f)).norm(), 1e-6f);
  EXPECT_NEAR(transform.stretch(), 0.5f, 1e-6f);
  EXPECT_NEAR(UvTransform::gltf({}, 0.4f, {3.f, -0.5f}).stretch(), 3.f, 1e-5f);
  // Half the scale, half the texels under a footprint: one level finer.
  const Texture plain("plain", quadrants);
  EXPECT_NEAR(plain.level_of_detail(0.5f) - texture.level_of_detail(0.5f), 1.f, 1e-6f);
}

TEST(Texture, WrapModesFollowTheGltfSampler) {
  const ColorImage image = image_of(2, 2, {kRed, kGreen, kBlue, kWhite});
  const Texture repeat("repeat", image, TextureWrap::Repeat, TextureWrap::Repeat);
  const Texture clamp("clamp", image, TextureWrap::ClampToEdge, TextureWrap::ClampToEdge);
  const Texture mirror("mirror", image, TextureWrap::MirroredRepeat, TextureWrap::MirroredRepeat);
  EXPECT_LT((repeat.sample(1.25f, 0.25f) - linear(kRed)).norm(), 1e-6f);
  EXPECT_LT((repeat.sample(-0.75f, 3.25f) - linear(kRed)).norm(), 1e-5f);
  EXPECT_LT((repeat.sample(4001.25f, 0.25f) - linear(kRed)).norm(), 1e-3f) << "far outside [0, 1]";
  EXPECT_LT((clamp.sample(-3.f, 0.25f) - linear(kRed)).norm(), 1e-6f);
  EXPECT_LT((clamp.sample(7.f, 0.75f) - linear(kWhite)).norm(), 1e-6f);
  EXPECT_LT((mirror.sample(1.25f, 0.25f) - linear(kGreen)).norm(), 1e-6f) << "[1, 2] runs backwards";
  EXPECT_LT((mirror.sample(2.25f, 0.25f) - linear(kRed)).norm(), 1e-6f);
}

using test::checkerboard;

TEST(Texture, MipLevelsAverageTheTexelsAbove) {
  const Texture texture("checker", checkerboard(64, 1, Rgb8{0, 0, 0}, Rgb8{255, 255, 255}));
  ASSERT_EQ(texture.levels(), 7);
  EXPECT_EQ(texture.level_width(1), 32);
  EXPECT_EQ(texture.level_width(6), 1);
  // Level 1 is grey everywhere: half black, half white in linear light (0.5 -> sRGB 188).
  EXPECT_NEAR(texture.sample(0.3f, 0.6f, 1.f).x(), 0.5f, 0.004f);
  EXPECT_NEAR(texture.mean().y(), 0.5f, 0.004f);
  EXPECT_NEAR(texture.sample(0.3f, 0.6f, 100.f).z(), 0.5f, 0.004f) << "lod clamps to the last level";
  // Footprints: one texel per pixel is level 0, four texels level 2.
  EXPECT_FLOAT_EQ(texture.level_of_detail(1.f / 64.f), 0.f);
  EXPECT_FLOAT_EQ(texture.level_of_detail(0.1f / 64.f), 0.f);
  EXPECT_NEAR(texture.level_of_detail(4.f / 64.f), 2.f, 1e-5f);
  // Odd sizes fold their last row and column into the level below.
  const Texture odd("odd", checkerboard(5, 1, Rgb8{0, 0, 0}, Rgb8{255, 255, 255}));
  EXPECT_EQ(odd.level_width(1), 2);
  EXPECT_EQ(odd.levels(), 3);
  EXPECT_NEAR(odd.mean().x(), 12.f / 25.f, 0.02f);  // 12 of the 25 texels are white
}

// ---- glTF ---------------------------------------------------------------------------------------

TEST(TexturedGltf, BoxTexturedLoadsItsBaseColourTextureAndCoordinates) {
  const VirtualModel box = load_model(std::filesystem::path(RELIGHT_TEST_DATA) / "models" / "box_textured.gltf");
  ASSERT_EQ(box.meshes.size(), 1u);
  const TriangleMesh& mesh = box.meshes[0];
  EXPECT_EQ(mesh.positions.size(), 24u);
  ASSERT_EQ(mesh.texcoords.size(), mesh.positions.size());
  float largest = 0.f;
  for (const Eigen::Vector2f& uv : mesh.texcoords) largest = std::max(largest, uv.maxCoeff());
  EXPECT_NEAR(largest, 6.f, 1e-3f) << "coordinates beyond 1: the sampler repeats";
  const Texture* texture = box.materials.at(mesh.triangle_material[0]).base_color.get();
  ASSERT_NE(texture, nullptr);
  EXPECT_EQ(texture->width(), 211);
  EXPECT_EQ(texture->height(), 211);
  EXPECT_EQ(texture->wrap_u(), TextureWrap::Repeat);
  // The Cesium logo: mostly white-ish with green and grey; not a flat colour.
  const Eigen::Vector3f a = texture->sample(0.1f, 0.1f), b = texture->sample(0.5f, 0.5f);
  EXPECT_GT((a - b).norm(), 0.05f);
}

/// A one-triangle glTF with a textured material in `dir`: buffer.bin holds positions and, unless
/// `with_texcoords` is false, TEXCOORD_0; the image is the file `image` (written by the caller).
std::filesystem::path write_textured_triangle(
    const std::filesystem::path& dir, bool with_texcoords,
    const std::string& material = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})") {
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float texcoords[6] = {0, 0, 1, 0, 0, 1};
  {
    std::ofstream bin(dir / "buffer.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(positions), sizeof positions);
    bin.write(reinterpret_cast<const char*>(texcoords), sizeof texcoords);
  }
  const std::string attributes = with_texcoords ? R"("POSITION": 0, "TEXCOORD_0": 1)" : R"("POSITION": 0)";
  const std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {)" +
                           attributes + R"(}, "material": 0}]}],
    "materials": [)" + material +
                           R"(],
    "textures": [{"source": 0}], "images": [{"uri": "texture.png"}],
    "buffers": [{"uri": "buffer.bin", "byteLength": 60}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}]})";
  std::filesystem::path path = dir / "triangle.gltf";
  std::ofstream(path) << json;
  return path;
}

std::string load_error(const std::filesystem::path& path) {
  try {
    (void)load_model(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(loaded)";
}

TEST(TexturedGltf, AnExternalPngTextureIsDecoded) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.png", checkerboard(4, 2, kRed, kBlue));
  const VirtualModel model = load_model(write_textured_triangle(dir.path(), true));
  const Texture* texture = model.materials.at(0).base_color.get();
  ASSERT_NE(texture, nullptr);
  EXPECT_LT((texture->sample(0.25f, 0.25f) - linear(kRed)).norm(), 1e-6f);
  EXPECT_LT((texture->sample(0.75f, 0.25f) - linear(kBlue)).norm(), 1e-6f);
  EXPECT_EQ(model.meshes.at(0).texcoords.size(), 3u);
}

TEST(TexturedGltf, AnEmissiveTextureMultipliesTheEmission) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.png", checkerboard(4, 2, kRed, kBlue));
  const VirtualModel model = load_model(
      write_textured_triangle(dir.path(), true, R"({"emissiveTexture": {"index": 0}, "emissiveFactor": [1, 0.5, 1]})"));
  const PhongMaterial& material = model.materials.at(0);
  EXPECT_EQ(material.base_color, nullptr);
  ASSERT_NE(material.emission_texture, nullptr);
  EXPECT_EQ(model.meshes.at(0).texcoords.size(), 3u) << "read for the emissive texture alone";
  EXPECT_LT((material.emission - Eigen::Vector3f(1.f, 0.5f, 1.f)).norm(), 1e-6f);
  // One TEXCOORD set per material: two different ones are refused.
  const std::string two_sets =
      R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "emissiveTexture": {"index": 0, "texCoord": 1}})";
  const std::string error = load_error(write_textured_triangle(dir.path(), true, two_sets));
  EXPECT_NE(error.find("different TEXCOORD sets (0, 1)"), std::string::npos) << error;
}

TEST(TexturedGltf, TextureTransformsAreReadWithTheirTexcoordOverride) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.png", checkerboard(4, 2, kRed, kBlue));
  const std::string transformed = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
      "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0.3, "scale": [2, 3]}}}}})";
  const VirtualModel model = load_model(write_textured_triangle(dir.path(), true, transformed));
  const Texture* texture = model.materials.at(0).base_color.get();
  ASSERT_NE(texture, nullptr);
  const UvTransform expected = UvTransform::gltf({0.5f, 0.f}, 0.3f, {2.f, 3.f});
  EXPECT_TRUE(texture->transform().linear.isApprox(expected.linear, 1e-6f));
  EXPECT_TRUE(texture->transform().offset.isApprox(expected.offset, 1e-6f));
  // The extension's texCoord overrides the reference's: set 1 against the emission's 0.
  const std::string overridden = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
      "extensions": {"KHR_texture_transform": {"texCoord": 1}}}}, "emissiveTexture": {"index": 0}})";
  const std::string error = load_error(write_textured_triangle(dir.path(), true, overridden));
  EXPECT_NE(error.find("different TEXCOORD sets (1, 0)"), std::string::npos) << error;
}

TEST(TexturedGltf, AMetallicRoughnessTextureIsReadAsLinearDataWithItsFactors) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.png", checkerboard(4, 2, kRed, kBlue));
  const std::string material = R"({"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0},
      "baseColorFactor": [0.2, 0.4, 0.6, 1], "metallicFactor": 0.5, "roughnessFactor": 0.8}})";
  const VirtualModel model = load_model(write_textured_triangle(dir.path(), true, material));
  const PhongMaterial& m = model.materials.at(0);
  ASSERT_NE(m.metallic_roughness_texture, nullptr);
  EXPECT_EQ(m.metallic_roughness_texture->encoding(), TextureEncoding::Linear);
  EXPECT_LT((m.metallic_roughness_texture->sample(0.75f, 0.25f) - Eigen::Vector3f(20.f, 40.f, 220.f) / 255.f).norm(),
            1e-6f);
  EXPECT_EQ(model.meshes.at(0).texcoords.size(), 3u) << "read for the metallic-roughness texture alone";
  EXPECT_LT((m.metallic_roughness.base_color - Eigen::Vector3f(0.2f, 0.4f, 0.6f)).norm(), 1e-6f);
  EXPECT_FLOAT_EQ(m.metallic_roughness.metallic, 0.5f);
  EXPECT_FLOAT_EQ(m.metallic_roughness.roughness, 0.8f);
  // The material's own Phong is the factors' (what a point without coordinates falls back to).
  EXPECT_LT((m.kd - Eigen::Vector3f(0.1f, 0.2f, 0.3f)).norm(), 1e-6f);
  // At a texel: roughness G x 0.8, metallic B x 0.5.
  const Phong at = surface_phong(m, Eigen::Vector3f(0.f, 0.5f, 1.f));
  const Phong expected = phong_from_metallic_roughness({{0.2f, 0.4f, 0.6f}, 0.5f, 0.4f});
  EXPECT_LT((at.kd - expected.kd).norm(), 1e-6f);
  EXPECT_FLOAT_EQ(at.ks, expected.ks);
  EXPECT_FLOAT_EQ(at.n, expected.n);
  EXPECT_GT(at.n, 5.f * m.n) << "smoother than the factor alone";

  // relight's own Phong parameters (extras) are kept as they are: the texture has nothing to map.
  const std::string extras = R"({"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0}},
      "extras": {"relight_phong": {"kd": [0.5, 0.5, 0.5], "ks": 0.1, "n": 20}}})";
  EXPECT_EQ(load_model(write_textured_triangle(dir.path(), true, extras)).materials.at(0).metallic_roughness_texture,
            nullptr);
  const std::string two_sets = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
      "metallicRoughnessTexture": {"index": 0, "texCoord": 2}}})";
  const std::string error = load_error(write_textured_triangle(dir.path(), true, two_sets));
  EXPECT_NE(error.find("different TEXCOORD sets (0, 2)"), std::string::npos) << error;
}

TEST(TexturedGltf, ANormalTextureIsReadAsLinearDataWithItsScale) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.png", checkerboard(4, 2, kRed, kBlue));
  const VirtualModel model =
      load_model(write_textured_triangle(dir.path(), true, R"({"normalTexture": {"index": 0, "scale": 0.5}})"));
  const PhongMaterial& material = model.materials.at(0);
  ASSERT_NE(material.normal_texture, nullptr);
  EXPECT_EQ(material.normal_texture->encoding(), TextureEncoding::Linear) << "normals are data, not colours";
  EXPECT_FLOAT_EQ(material.normal_scale, 0.5f);
  EXPECT_LT((material.normal_texture->sample(0.25f, 0.25f) - Eigen::Vector3f(200.f, 30.f, 20.f) / 255.f).norm(), 1e-6f);
  EXPECT_EQ(model.meshes.at(0).texcoords.size(), 3u) << "read for the normal texture alone";
}

TEST(TexturedGltf, AJpegTextureIsDecodedByItsSignature) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.jpg", checkerboard(32, 16, kRed, kBlue));
  std::filesystem::copy_file(dir.path() / "texture.jpg", dir.path() / "texture.png");
  const VirtualModel model = load_model(write_textured_triangle(dir.path(), true));
  const Texture* texture = model.materials.at(0).base_color.get();
  ASSERT_NE(texture, nullptr);
  EXPECT_EQ(texture->width(), 32);
  EXPECT_LT((texture->sample(0.25f, 0.25f) - linear(kRed)).norm(), 0.05f) << "JPEG is lossy";
  EXPECT_LT((texture->sample(0.75f, 0.25f) - linear(kBlue)).norm(), 0.05f);
}

// The common case of real models: a .glb whose image is a buffer view of its BIN chunk.
TEST(TexturedGltf, AGlbTextureInABufferViewIsDecoded) {
  const relight::test::TempDir dir;
  write_color(dir.path() / "texture.png", checkerboard(8, 4, kGreen, kWhite));
  std::ifstream png_file(dir.path() / "texture.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(png_file)), std::istreambuf_iterator<char>());
  const float geometry[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};  // positions, then texcoords
  std::string bin(reinterpret_cast<const char*>(geometry), sizeof geometry);
  bin += png;
  while (bin.size() % 4 != 0) bin += '\0';
  const std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
    "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "samplers": [{"wrapS": 33071, "wrapT": 33648}],
    "textures": [{"source": 0, "sampler": 0}], "images": [{"bufferView": 2, "mimeType": "image/png"}],
    "buffers": [{"byteLength": )" +
                           std::to_string(bin.size()) + R"(}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                    {"buffer": 0, "byteOffset": 60, "byteLength": )" +
                           std::to_string(png.size()) + R"(}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}]})";
  std::ofstream(dir.path() / "triangle.glb", std::ios::binary) << relight::test::glb(json, bin);
  const VirtualModel model = load_model(dir.path() / "triangle.glb");
  const Texture* texture = model.materials.at(0).base_color.get();
  ASSERT_NE(texture, nullptr);
  EXPECT_EQ(texture->wrap_u(), TextureWrap::ClampToEdge);
  EXPECT_EQ(texture->wrap_v(), TextureWrap::MirroredRepeat);
  EXPECT_LT((texture->sample(0.25f, 0.25f) - linear(kGreen)).norm(), 1e-6f);
  EXPECT_LT((texture->sample(0.75f, 0.25f) - linear(kWhite)).norm(), 1e-6f);
}

TEST(TexturedGltf, BrokenTexturesFailWithOneLineNamingTheImage) {
  const relight::test::TempDir dir;
  const std::filesystem::path triangle = write_textured_triangle(dir.path(), true);
  std::ofstream(dir.path() / "texture.png") << "not an image at all";
  EXPECT_NE(load_error(triangle).find("image 0 (texture.png)"), std::string::npos) << load_error(triangle);
  EXPECT_NE(load_error(triangle).find("not a PNG or JPEG"), std::string::npos) << load_error(triangle);

  // A PNG header that claims 40000 x 40000 pixels is refused before anything is decoded.
  std::string header("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
  for (const std::uint32_t side : {40000u, 40000u})
    for (int shift = 24; shift >= 0; shift -= 8) header += static_cast<char>((side >> shift) & 0xffu);
  header += std::string("\x08\x02\0\0\0", 5);
  std::ofstream(dir.path() / "texture.png", std::ios::binary) << header;
  EXPECT_NE(load_error(triangle).find("40000x40000 image, larger than 8192"), std::string::npos)
      << load_error(triangle);

  // A JPEG whose frame header (after an APP0 segment) claims 30000 x 20000.
  const std::string app0("\xff\xe0\x00\x04\x00\x00", 6);
  const std::string sof0("\xff\xc0\x00\x11\x08\x4e\x20\x75\x30\x03", 10);
  std::ofstream(dir.path() / "texture.png", std::ios::binary) << std::string("\xff\xd8", 2) + app0 + sof0;
  EXPECT_NE(load_error(triangle).find("30000x20000 image, larger than 8192"), std::string::npos)
      << load_error(triangle);

  // A truncated PNG (the signature only).
  std::ofstream(dir.path() / "texture.png", std::ios::binary) << std::string("\x89PNG\r\n\x1a\n", 8);
  EXPECT_NE(load_error(triangle).find("header is missing or cut short"), std::string::npos) << load_error(triangle);

  write_color(dir.path() / "texture.png", checkerboard(4, 2, kRed, kBlue));
  const std::filesystem::path without = write_textured_triangle(dir.path(), false);
  EXPECT_NE(load_error(without).find("has a textured material but no TEXCOORD_0"), std::string::npos)
      << load_error(without);
}

// ---- rendering ----------------------------------------------------------------------------------

constexpr float kSun = 2.f;  // irradiance at normal incidence

/// A virtual sun straight above, irradiance kSun.
void add_sun_overhead(MrScene& scene) {
  MrLight sun;
  sun.kind = LightKind::Directional;
  sun.direction = Eigen::Vector3f::UnitZ();
  sun.intensity = Eigen::Vector3f::Constant(kSun);
  sun.real = false;
  scene.lights.push_back(sun);
}

/// A virtual 1 m square at z = 0.2 facing up, textured with a 4x4-cell checkerboard of red and
/// blue (coordinates 0..1 across it), k_d 0.8, under a sun straight above; nothing else.
MrScene textured_square() {
  MrScene scene;
  PhongMaterial material = test::diffuse({0.8f, 0.8f, 0.8f}, "checker");
  material.base_color = std::make_shared<const Texture>("checker", checkerboard(64, 16, kRed, kBlue));
  TriangleMesh square;
  square.name = "square";
  square.real = false;
  square.positions = {{-0.5f, -0.5f, 0.2f}, {0.5f, -0.5f, 0.2f}, {0.5f, 0.5f, 0.2f}, {-0.5f, 0.5f, 0.2f}};
  square.normals.assign(4, Eigen::Vector3f::UnitZ());
  square.texcoords = {{0.f, 1.f}, {1.f, 1.f}, {1.f, 0.f}, {0.f, 0.f}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  square.triangle_material = {scene.add_material(material), 0};
  square.triangle_material[1] = square.triangle_material[0];
  scene.meshes.push_back(square);
  add_sun_overhead(scene);
  return scene;
}

/// Pixels whose centre sees the middle of a checker cell (not within 2 texels of a cell edge),
/// with the colour the closed form gives there: k_d t / pi E.
struct Expected {
  int x, y;
  Eigen::Vector3f radiance;
};

std::vector<Expected> cell_centres(const GBuffer& gbuffer) {
  std::vector<Expected> out;
  for (int y = 0; y < gbuffer.distance.height(); ++y)
    for (int x = 0; x < gbuffer.distance.width(); ++x) {
      if (gbuffer.distance(y, x) == 0.f) continue;
      const Float3& p = gbuffer.position(y, x);
      const float u = p.x + 0.5f, v = 0.5f - p.y;  // the square's coordinates
      const float cu = u * 4.f - std::floor(u * 4.f), cv = v * 4.f - std::floor(v * 4.f);
      if (std::min({cu, cv, 1.f - cu, 1.f - cv}) < 0.15f) continue;
      const bool red = (static_cast<int>(u * 4.f) + static_cast<int>(v * 4.f)) % 2 == 0;
      out.push_back({x, y, 0.8f * linear(red ? kRed : kBlue) * (kSun / std::numbers::pi_v<float>)});
    }
  return out;
}

/// The CPU DIR's direct light alone (no VPLs), with its G-buffer.
DifferentialImages direct_light(const MrScene& scene, const MrCamera& camera, GBuffer& gbuffer) {
  DirRenderOptions options;
  options.shadow_tile = 128;
  options.shading.indirect = false;
  return render_dir_cpu(scene, camera, {}, options, &gbuffer);
}

/// The path tracer's direct light (and emission) alone, `spp` samples per pixel.
DifferentialImages path_traced_direct(const MrScene& scene, const MrCamera& camera, int spp) {
  DifferentialPathTracer tracer(scene, {.max_bounces = 0});
  tracer.reset(camera);
  tracer.render(spp);
  return tracer.images();
}

TEST(TexturedRendering, DirDirectLightFollowsTheTexture) {
  const MrScene scene = textured_square();
  const MrCamera camera = test::camera_at({0.05, -0.6, 1.4}, {0, 0, 0.2}, 80, 60);
  GBuffer gbuffer;
  const DifferentialImages images = direct_light(scene, camera, gbuffer);
  ASSERT_FALSE(gbuffer.texcoord.empty());
  const std::vector<Expected> cells = cell_centres(gbuffer);
  ASSERT_GT(cells.size(), 300u);
  int red = 0, blue = 0;
  for (const Expected& e : cells) {
    const Float3& c = images.real_virtual(e.y, e.x);
    EXPECT_LT((Eigen::Vector3f(c.x, c.y, c.z) - e.radiance).norm(), 2e-3f * e.radiance.norm() + 1e-4f)
        << "pixel " << e.x << "," << e.y;
    (e.radiance.x() > e.radiance.z() ? red : blue)++;
  }
  EXPECT_GT(red, 100);
  EXPECT_GT(blue, 100);
}

// Khronos' BoxTextured, as shipped, in DIR: at every pixel of its upward face where the decoded
// image is uniform around the pixel's texel (so that filtering cannot change it), the rendered
// radiance is the Phong model with k_d = that texel, under a sun straight above.
TEST(TexturedRendering, BoxTexturedShowsItsDecodedImage) {
  const VirtualModel box = load_model(std::filesystem::path(RELIGHT_TEST_DATA) / "models" / "box_textured.gltf");
  MrScene scene;
  add_virtual_model(scene, box, Placement{});
  add_sun_overhead(scene);
  // About one texel per pixel on the top face (211 texels across 1 m, seen from 1.35 m).
  const MrCamera camera = test::camera_at({0.01, -0.02, 1.85}, {0, 0, 0.5}, 320, 240);
  GBuffer gbuffer;
  const DifferentialImages images = direct_light(scene, camera, gbuffer);
  const PhongMaterial& material = scene.materials.at(gbuffer.material(120, 160) - 1u);
  ASSERT_NE(material.base_color, nullptr);
  const Texture& texture = *material.base_color;
  const int w = texture.width(), h = texture.height();
  const auto texel = [&](int x, int y) {
    const std::uint32_t t = texture.texels()[static_cast<std::size_t>(((y % h) + h) % h) * static_cast<std::size_t>(w) +
                                             static_cast<std::size_t>(((x % w) + w) % w)];
    return Eigen::Vector3i(int(t & 0xffu), int((t >> 8) & 0xffu), int((t >> 16) & 0xffu));
  };
  const Eigen::Vector3f eye = camera.camera_to_world.translation().cast<float>();
  int checked = 0, distinct_colours = 0;
  Eigen::Vector3i first_colour(-1, -1, -1);
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      if (gbuffer.distance(y, x) == 0.f || gbuffer.normal(y, x).z < 0.999f) continue;
      const Float3& t = gbuffer.texcoord(y, x);
      ASSERT_GT(t.z, 0.f);
      // Levels 0 and 1 only, whose bilinear taps lie within 3 texels of the pixel's own.
      if (texture.level_of_detail(t.z) >= 1.f) continue;
      const int tx = static_cast<int>(std::floor(t.x * float(w))), ty = static_cast<int>(std::floor(t.y * float(h)));
      const Eigen::Vector3i centre = texel(tx, ty);
      bool uniform = true;
      for (int j = -3; j <= 3; ++j)
        for (int i = -3; i <= 3; ++i) uniform = uniform && (texel(tx + i, ty + j) - centre).cwiseAbs().maxCoeff() <= 1;
      if (!uniform) continue;
      ++checked;
      if (first_colour.x() < 0) first_colour = centre;
      if ((centre - first_colour).cwiseAbs().maxCoeff() > 40) ++distinct_colours;
      Phong at_texel = material;
      at_texel.kd = material.kd.cwiseProduct(Eigen::Vector3f(srgb_to_linear(std::uint8_t(centre.x())),
                                                             srgb_to_linear(std::uint8_t(centre.y())),
                                                             srgb_to_linear(std::uint8_t(centre.z()))));
      const Float3& p = gbuffer.position(y, x);
      const Eigen::Vector3f point(p.x, p.y, p.z);
      const Eigen::Vector3f expected = phong_brdf(at_texel, Eigen::Vector3f::UnitZ().eval(), scene.lights[0].direction,
                                                  (eye - point).normalized().eval()) *
                                       kSun;
      const Float3& c = images.real_virtual(y, x);
      EXPECT_LT((Eigen::Vector3f(c.x, c.y, c.z) - expected).norm(), 0.01f * expected.norm() + 2e-3f)
          << "pixel " << x << "," << y << " texel " << centre.transpose();
    }
  std::printf("BoxTextured top face: %d pixels checked against their texel, %d of another colour than the first\n",
              checked, distinct_colours);
  EXPECT_GT(checked, 5000) << "the top face fills much of the view";
  EXPECT_GT(distinct_colours, 500) << "the logo's colours, not one flat colour";
}

// The same square glowing through its emission texture, unlit: L = emission t in DIR and in
// the path tracer.
TEST(TexturedRendering, EmissionFollowsTheEmissionTexture) {
  MrScene scene = textured_square();
  scene.lights.clear();
  PhongMaterial& material = scene.materials[0];
  material.emission = {0.5f, 1.f, 2.f};
  material.emission_texture = std::exchange(material.base_color, nullptr);
  const MrCamera camera = test::camera_at({0.05, -0.6, 1.4}, {0, 0, 0.2}, 40, 30);
  GBuffer gbuffer;
  const DifferentialImages dir = direct_light(scene, camera, gbuffer);
  const DifferentialImages traced = path_traced_direct(scene, camera, 4);
  const std::vector<Expected> cells = cell_centres(gbuffer);
  ASSERT_GT(cells.size(), 60u);
  for (const Expected& e : cells) {
    // cell_centres' radiance is 0.8 t E / pi; the emission is (0.5, 1, 2) t.
    const Eigen::Vector3f expected =
        (e.radiance * (std::numbers::pi_v<float> / (0.8f * kSun))).cwiseProduct(material.emission);
    for (const DifferentialImages* images : {&dir, &traced}) {
      const Float3& c = images->real_virtual(e.y, e.x);
      EXPECT_LT((Eigen::Vector3f(c.x, c.y, c.z) - expected).norm(), 0.01f * expected.norm() + 1e-4f)
          << "pixel " << e.x << "," << e.y << (images == &dir ? " (DIR)" : " (path tracer)");
    }
  }
}

// The square's checker cells alternate between a rough red dielectric and a blue-based metal of
// medium roughness through a metallic-roughness texture (the base colour texture stays): each
// cell's light is the Phong model of its own texel's mapping, in DIR and in the path tracer; the
// metal cells lose the texture's blue (k_d = 0) and show k_s's broad highlight instead.
TEST(TexturedRendering, MetallicRoughnessTextureSetsThePhongParametersPerPoint) {
  MrScene scene = textured_square();
  PhongMaterial& material = scene.materials[0];
  const Rgb8 dielectric{0, 230, 0}, metal{0, 200, 255};  // glTF: G roughness, B metallic
  material.metallic_roughness_texture = std::make_shared<const Texture>(
      "mr", checkerboard(64, 16, dielectric, metal), TextureWrap::Repeat, TextureWrap::Repeat, TextureEncoding::Linear);
  material.metallic_roughness = {Eigen::Vector3f::Constant(0.8f), 1.f, 1.f};
  static_cast<Phong&>(material) = phong_from_metallic_roughness(material.metallic_roughness);
  const MrCamera camera = test::camera_at({0.05, -0.6, 1.4}, {0, 0, 0.2}, 80, 60);
  GBuffer gbuffer;
  const DifferentialImages dir = direct_light(scene, camera, gbuffer);
  const DifferentialImages traced = path_traced_direct(scene, camera, 8);
  const Eigen::Vector3f eye = camera.camera_to_world.translation().cast<float>();
  int metal_cells = 0, dielectric_cells = 0;
  for (const Expected& e : cell_centres(gbuffer)) {
    const bool red = e.radiance.x() > e.radiance.z();
    const Rgb8 texel = red ? dielectric : metal;
    Phong at = phong_from_metallic_roughness(
        {Eigen::Vector3f::Constant(0.8f), float(texel.b) / 255.f, float(texel.g) / 255.f});
    at = with_kd_factor(at, linear(red ? kRed : kBlue));
    const Float3& p = gbuffer.position(e.y, e.x);
    const Eigen::Vector3f point(p.x, p.y, p.z);
    const Eigen::Vector3f expected =
        phong_brdf(at, Eigen::Vector3f::UnitZ().eval(), scene.lights[0].direction, (eye - point).normalized().eval()) *
        kSun;
    for (const DifferentialImages* images : {&dir, &traced}) {
      const Float3& c = images->real_virtual(e.y, e.x);
      EXPECT_LT((Eigen::Vector3f(c.x, c.y, c.z) - expected).norm(), 0.01f * expected.norm() + 1e-4f)
          << "pixel " << e.x << "," << e.y << (images == &dir ? " (DIR)" : " (path tracer)");
    }
    if (red) {
      ++dielectric_cells;
    } else {
      ++metal_cells;
      const Float3& c = dir.real_virtual(e.y, e.x);
      EXPECT_LT(c.z, 1.2f * c.x) << "a metal's white highlight, not the base texture's blue";
      EXPECT_GT(c.x, 0.05f) << "k_s = 0.8 with n = " << at.n;
    }
  }
  EXPECT_GT(metal_cells, 100);
  EXPECT_GT(dielectric_cells, 100);
}

TEST(TexturedRendering, PathTracerFollowsTheTexture) {
  const MrScene scene = textured_square();
  const MrCamera camera = test::camera_at({0.05, -0.6, 1.4}, {0, 0, 0.2}, 40, 30);
  const GBuffer gbuffer = gbuffer_cpu(RayTracer(scene), camera);
  const DifferentialImages images = path_traced_direct(scene, camera, 16);
  const std::vector<Expected> cells = cell_centres(gbuffer);
  ASSERT_GT(cells.size(), 60u);
  for (const Expected& e : cells) {
    const Float3& c = images.real_virtual(e.y, e.x);
    // The pixel's samples spread over its footprint; at cell centres it lies inside one colour.
    EXPECT_LT((Eigen::Vector3f(c.x, c.y, c.z) - e.radiance).norm(), 0.01f * e.radiance.norm() + 1e-4f)
        << "pixel " << e.x << "," << e.y;
  }
}

TEST(TexturedRendering, DistantTexturesAreFilteredToTheirMean) {
  // A fine checkerboard (1-texel cells, 512 texels across the square) seen from afar: at ~35
  // texels per pixel the G-buffer's footprint picks a level near 5, where black and white
  // average to grey, instead of aliasing to one of them.
  MrScene scene = textured_square();
  scene.materials[0].base_color =
      std::make_shared<const Texture>("fine", checkerboard(512, 1, Rgb8{0, 0, 0}, Rgb8{255, 255, 255}));
  const MrCamera camera = test::camera_at({0.0, -0.2, 4.0}, {0, 0, 0.2}, 64, 48);
  GBuffer gbuffer;
  const DifferentialImages images = direct_light(scene, camera, gbuffer);
  const float grey = 0.8f * 0.5f * kSun / std::numbers::pi_v<float>;
  int seen = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      if (gbuffer.distance(y, x) == 0.f) continue;
      ++seen;
      EXPECT_GT(gbuffer.texcoord(y, x).z, 2.f / 512.f) << "several texels per pixel";
      EXPECT_NEAR(images.real_virtual(y, x).x, grey, 0.1f * grey) << "pixel " << x << "," << y;
    }
  EXPECT_GT(seen, 100);
}

}  // namespace
}  // namespace relight::render
