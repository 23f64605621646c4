#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>

#include "glb_file.h"
#include "relight/core/error.h"
#include "relight/render/scene/model_io.h"
#include "relight/render/scene/procedural_models.h"
#include "temp_dir.h"

namespace relight::render {
namespace {

void expect_same_geometry(const VirtualModel& a, const VirtualModel& b, float tolerance) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (std::size_t m = 0; m < a.meshes.size(); ++m) {
    ASSERT_EQ(a.meshes[m].triangle_count(), b.meshes[m].triangle_count());
    // Compare triangle corners (vertex numbering may differ between formats).
    for (std::size_t t = 0; t < a.meshes[m].triangle_count(); t += 7)
      for (int c = 0; c < 3; ++c) {
        const auto ca = static_cast<std::size_t>(c);
        EXPECT_LT((a.meshes[m].positions[a.meshes[m].triangles[t][ca]] - b.meshes[m].positions[b.meshes[m].triangles[t][ca]]).norm(),
                  tolerance);
        EXPECT_GT(a.meshes[m].normals[a.meshes[m].triangles[t][ca]].dot(b.meshes[m].normals[b.meshes[m].triangles[t][ca]]),
                  0.999f);
      }
  }
}

using test::glb;

void expect_same_material(const PhongMaterial& a, const PhongMaterial& b) {
  EXPECT_TRUE(a.kd.isApprox(b.kd, 1e-5f)) << a.name;
  EXPECT_NEAR(a.ks, b.ks, 1e-5f);
  EXPECT_NEAR(a.n, b.n, 1e-3f);
  EXPECT_TRUE(a.emission.isApprox(b.emission, 1e-5f) || (a.emission.isZero() && b.emission.isZero()));
}

TEST(ProceduralModels, PebbleIsClosedSmoothAndStandsOnItsBase) {
  const VirtualModel pebble = make_glossy_pebble();
  const Eigen::AlignedBox3f box = bounds(pebble);
  EXPECT_NEAR(box.min().y(), 0.f, 1e-6f);
  EXPECT_GT(box.max().y(), 0.08f);
  EXPECT_LT(box.max().y(), 0.14f);
  EXPECT_NEAR(box.center().x(), 0.f, 0.02f);
  const TriangleMesh& mesh = pebble.meshes.front();
  // Closed: every edge is shared by exactly two triangles (Euler characteristic 2).
  const long long v = static_cast<long long>(mesh.positions.size());
  const long long f = static_cast<long long>(mesh.triangle_count());
  EXPECT_EQ(v - 3 * f / 2 + f, 2);
  const Eigen::Vector3f centre = box.center();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    EXPECT_GT((mesh.positions[i] - centre).normalized().dot(mesh.normals[i]), 0.5f) << "normals point outwards";
}

TEST(ModelIo, ObjAndGltfRoundTripGeometryAndPhongMaterials) {
  const test::TempDir dir;
  for (const VirtualModel& model : {make_glossy_pebble(24), make_matte_box()}) {
    save_obj(dir.path() / (model.name + ".obj"), model);
    save_gltf(dir.path() / (model.name + ".gltf"), model);
    const VirtualModel from_obj = load_model(dir.path() / (model.name + ".obj"));
    const VirtualModel from_gltf = load_model(dir.path() / (model.name + ".gltf"));
    expect_same_geometry(model, from_obj, 1e-6f);
    expect_same_geometry(model, from_gltf, 0.f + 1e-7f);
    expect_same_material(model.materials[0], from_obj.materials[0]);
    expect_same_material(model.materials[0], from_gltf.materials[0]);
  }
}

TEST(ModelIo, EmissiveMaterialSurvivesGltf) {
  const test::TempDir dir;
  VirtualModel lamp = make_matte_box();
  lamp.materials[0].emission = {4.f, 3.f, 2.f};
  save_gltf(dir.path() / "lamp.gltf", lamp);
  EXPECT_TRUE(load_model(dir.path() / "lamp.gltf").materials[0].emission.isApprox(Eigen::Vector3f(4, 3, 2), 1e-5f));
}

TEST(ModelIo, GlassAndMirrorMaterialsSurviveGltf) {
  const test::TempDir dir;
  VirtualModel model = make_matte_box();
  model.materials[0].specular = dielectric(1.33f, {0.6f, 0.9f, 1.f}, 0.05f);
  model.materials.push_back(model.materials[0]);
  model.materials[1].name = "mirror";
  model.materials[1].specular = conductor({0.95f, 0.64f, 0.54f});
  model.meshes[0].triangle_material[0] = 1;
  save_gltf(dir.path() / "specular.gltf", model);
  const VirtualModel back = load_model(dir.path() / "specular.gltf");
  ASSERT_EQ(back.materials.size(), 3u);  // + the default material
  const SpecularMaterial& glass = back.materials[0].specular;
  EXPECT_EQ(glass.kind, SpecularKind::Dielectric);
  EXPECT_FLOAT_EQ(glass.ior, 1.33f);
  EXPECT_TRUE(glass.attenuation_color.isApprox(Eigen::Vector3f(0.6f, 0.9f, 1.f)));
  EXPECT_FLOAT_EQ(glass.attenuation_distance, 0.05f);
  EXPECT_EQ(back.materials[1].specular.kind, SpecularKind::Conductor);
  EXPECT_TRUE(back.materials[1].specular.reflectance.isApprox(Eigen::Vector3f(0.95f, 0.64f, 0.54f)));
  expect_same_material(model.materials[0], back.materials[0]);  // the Phong fallback too
  EXPECT_FALSE(back.materials[2].specular.specular());
}

TEST(ModelIo, GltfTransmissionMakesGlassAndASmoothMetalAMirror) {
  const test::TempDir dir;
  save_gltf(dir.path() / "box.gltf", make_matte_box());
  nlohmann::json gltf = nlohmann::json::parse(std::ifstream(dir.path() / "box.gltf"));
  const auto write_with = [&](const nlohmann::json& material) {
    gltf["materials"] = nlohmann::json::array({material});
    std::ofstream(dir.path() / "variant.gltf") << gltf.dump();
    return load_model(dir.path() / "variant.gltf").materials[0];
  };
  // Glass without an index (1.5) and with a volume's attenuation; its Phong fallback is clear.
  const PhongMaterial glass = write_with(nlohmann::json::parse(R"({"name": "glass",
      "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                     "KHR_materials_volume": {"attenuationColor": [0.5, 0.5, 1], "attenuationDistance": 0.2}}})"));
  EXPECT_EQ(glass.specular.kind, SpecularKind::Dielectric);
  EXPECT_FLOAT_EQ(glass.specular.ior, 1.5f);
  EXPECT_TRUE(glass.specular.attenuation_color.isApprox(Eigen::Vector3f(0.5f, 0.5f, 1.f)));
  EXPECT_FLOAT_EQ(glass.specular.attenuation_distance, 0.2f);
  EXPECT_LT(glass.kd.maxCoeff(), 1e-6f);
  const PhongMaterial water = write_with(nlohmann::json::parse(R"({"name": "water",
      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.9}, "KHR_materials_ior": {"ior": 1.33}}})"));
  EXPECT_FLOAT_EQ(water.specular.ior, 1.33f);
  EXPECT_FALSE(std::isfinite(water.specular.attenuation_distance));
  const PhongMaterial copper = write_with(nlohmann::json::parse(R"({"name": "copper",
      "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.64, 0.54, 1], "metallicFactor": 1, "roughnessFactor": 0.02}})"));
  EXPECT_EQ(copper.specular.kind, SpecularKind::Conductor);
  EXPECT_TRUE(copper.specular.reflectance.isApprox(Eigen::Vector3f(0.95f, 0.64f, 0.54f)));
  // Rough metal and a little transmission stay Phong.
  EXPECT_FALSE(
      write_with(nlohmann::json::parse(R"({"pbrMetallicRoughness": {"metallicFactor": 1, "roughnessFactor": 0.4}})"))
          .specular.specular());
  EXPECT_FALSE(write_with(nlohmann::json::parse(
                              R"({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.2}}})"))
                   .specular.specular());
}

// Bad glass is one line naming the file; what the loader cannot honour is a warning.
TEST(ModelIo, BadGlassIsAnErrorAndOpenGlassOrAnUnknownExtensionAWarning) {
  const test::TempDir dir;
  save_gltf(dir.path() / "box.gltf", make_matte_box());
  nlohmann::json gltf = nlohmann::json::parse(std::ifstream(dir.path() / "box.gltf"));
  const auto glass = [](double ior) {
    return nlohmann::json{
        {"name", "glass"},
        {"extensions",
         {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}, {"KHR_materials_ior", {{"ior", ior}}}}}};
  };
  gltf["materials"] = nlohmann::json::array({glass(0.5)});
  std::ofstream(dir.path() / "thin_air.gltf") << gltf.dump();
  try {
    (void)load_model(dir.path() / "thin_air.gltf");
    ADD_FAILURE() << "an index of refraction of 0.5 was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("thin_air.gltf"), std::string::npos) << message;
    EXPECT_NE(message.find("index of refraction"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // The closed box in glass: no warning. Without its top face: open.
  gltf["materials"] = nlohmann::json::array({glass(1.5)});
  std::ofstream(dir.path() / "glass_box.gltf") << gltf.dump();
  EXPECT_TRUE(load_model(dir.path() / "glass_box.gltf").warnings.empty());
  VirtualModel open_box = make_matte_box();
  open_box.materials[0].specular = dielectric(1.5f);
  open_box.meshes[0].triangles.resize(open_box.meshes[0].triangles.size() - 2);
  open_box.meshes[0].triangle_material.resize(open_box.meshes[0].triangles.size());
  save_gltf(dir.path() / "open.gltf", open_box);
  const VirtualModel open = load_model(dir.path() / "open.gltf");
  ASSERT_EQ(open.warnings.size(), 1u);
  EXPECT_NE(open.warnings[0].find("not a closed surface"), std::string::npos) << open.warnings[0];
  gltf["extensionsUsed"] = nlohmann::json::array({"KHR_materials_sheen"});
  std::ofstream(dir.path() / "sheen.gltf") << gltf.dump();
  const VirtualModel sheen = load_model(dir.path() / "sheen.gltf");
  ASSERT_EQ(sheen.warnings.size(), 1u);
  EXPECT_NE(sheen.warnings[0].find("KHR_materials_sheen"), std::string::npos) << sheen.warnings[0];
}

TEST(ProceduralModels, TheGlassPebbleAndTheMetalBottleAreClosedAndWoundOutwards) {
  // Glass needs both: the winding says whether a ray enters or leaves (specular_material.h).
  const std::vector<VirtualModel> models{make_glass_pebble(), make_metal_bottle()};
  for (const VirtualModel& model : models) {
    const TriangleMesh& mesh = model.meshes.at(0);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed_edges;
    double volume = 0.0;  // divergence theorem: positive for outward windings
    for (const auto& t : mesh.triangles) {
      for (int e = 0; e < 3; ++e)
        ++directed_edges[{t[static_cast<std::size_t>(e)], t[static_cast<std::size_t>((e + 1) % 3)]}];
      volume += mesh.positions[t[0]].cast<double>().dot(
                    mesh.positions[t[1]].cast<double>().cross(mesh.positions[t[2]].cast<double>())) /
                6.0;
    }
    for (const auto& [edge, count] : directed_edges) {
      EXPECT_EQ(count, 1) << model.name;  // each directed edge once, and its reverse once: closed
      EXPECT_EQ(directed_edges.count({edge.second, edge.first}), 1u) << model.name;
    }
    EXPECT_GT(volume, 0.0) << model.name;
    EXPECT_TRUE(model.materials.at(0).specular.specular()) << model.name;
  }
  // The bottle's volume is about that of its profile turned (a 7 cm cylinder 0.11 m high plus neck).
  const TriangleMesh& bottle = models[1].meshes.at(0);
  double volume = 0.0;
  for (const auto& t : bottle.triangles)
    volume += bottle.positions[t[0]].cast<double>().dot(
                  bottle.positions[t[1]].cast<double>().cross(bottle.positions[t[2]].cast<double>())) /
              6.0;
  EXPECT_GT(volume, std::numbers::pi * 0.035 * 0.035 * 0.11);
  EXPECT_LT(volume, std::numbers::pi * 0.035 * 0.035 * 0.21);
}

TEST(ModelIo, ShippedModelsAreTheProceduralOnes) {
  const std::filesystem::path models = std::filesystem::path(RELIGHT_TEST_DATA) / "models";
  const VirtualModel pebble = load_model(models / "glossy_pebble.gltf");
  expect_same_geometry(make_glossy_pebble(), pebble, 1e-6f);
  expect_same_material(make_glossy_pebble().materials[0], pebble.materials[0]);
  const std::vector<VirtualModel> specular_models{make_glass_pebble(), make_metal_bottle()};
  for (const VirtualModel& model : specular_models) {
    const VirtualModel shipped = load_model(models / (model.name + ".gltf"));
    expect_same_geometry(model, shipped, 1e-6f);
    EXPECT_EQ(shipped.materials[0].specular.kind, model.materials[0].specular.kind) << model.name;
  }
  const VirtualModel box = load_model(models / "matte_box.obj");
  expect_same_geometry(make_matte_box(), box, 1e-6f);
  expect_same_material(make_matte_box().materials[0], box.materials[0]);
}

TEST(ModelIo, BadFilesGiveOneLineErrorsNamingTheFile) {
  const test::TempDir dir;
  const auto expect_error = [](const std::filesystem::path& path) {
    try {
      (void)load_model(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path.filename().string()), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  expect_error(dir.path() / "missing.gltf");
  std::ofstream(dir.path() / "garbage.gltf") << "{ not json";
  expect_error(dir.path() / "garbage.gltf");
  std::ofstream(dir.path() / "empty.obj") << "# nothing\n";
  expect_error(dir.path() / "empty.obj");
  std::ofstream(dir.path() / "model.ply") << "ply\n";
  expect_error(dir.path() / "model.ply");
  // A glTF whose accessor points past its buffer.
  save_gltf(dir.path() / "box.gltf", make_matte_box());
  std::string text;
  {
    std::ifstream in(dir.path() / "box.gltf");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto count = text.find("\"count\": 24");
  ASSERT_NE(count, std::string::npos);
  text.replace(count, 11, "\"count\": 99999");
  std::ofstream(dir.path() / "truncated.gltf") << text;
  expect_error(dir.path() / "truncated.gltf");
  // A GLB whose buffer is empty: tinygltf 2.7 throws std::out_of_range on it (found by fuzzing).
  std::ofstream(dir.path() / "empty_buffer.glb", std::ios::binary)
      << glb(R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":0}]})", std::string(4, '\0'));
  expect_error(dir.path() / "empty_buffer.glb");
}

TEST(Placement, ParsesAndTurnsYUpIntoZUp) {
  const Placement p = Placement::parse("0.3,-0.2,0.75,90,2");
  EXPECT_TRUE(p.position.isApprox(Eigen::Vector3d(0.3, -0.2, 0.75)));
  // Model up (+y) becomes world up (+z); yaw 90 deg turns model +x into world +y.
  const Eigen::Affine3d t = p.transform();
  EXPECT_TRUE((t.linear() * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d(0, 0, 2), 1e-12));
  EXPECT_TRUE((t.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d(0, 2, 0), 1e-12));
  EXPECT_THROW((void)Placement::parse("1,2"), Error);
  EXPECT_THROW((void)Placement::parse("1,2,x"), Error);
  EXPECT_THROW((void)Placement::parse("1,2,3,0,-1"), Error);
}

// A placement on a real surface: the model's up axis follows the surface normal, yaw turns about
// it, and for up = z the transform is --place's.
TEST(Placement, StandsTheModelAlongTheSurfaceNormal) {
  Placement p = Placement::parse("0.3,-0.2,0.75,90");
  const Eigen::Affine3d z_up = p.transform();
  p.up = Eigen::Vector3d::UnitZ();
  EXPECT_TRUE(p.transform().isApprox(z_up, 1e-12));
  p.up = Eigen::Vector3d(1, 0, 1).normalized();  // a 45-degree slope facing +x
  const Eigen::Affine3d t = p.transform();
  EXPECT_TRUE((t.linear() * Eigen::Vector3d::UnitY()).isApprox(p.up, 1e-12));
  EXPECT_NEAR(t.linear().determinant(), 1.0, 1e-12);
  EXPECT_TRUE((t * Eigen::Vector3d::Zero()).isApprox(p.position, 1e-12));
  // Yaw still turns about the model's up: the model's +x stays perpendicular to up.
  EXPECT_NEAR((t.linear() * Eigen::Vector3d::UnitX()).dot(p.up), 0.0, 1e-12);
  p.up = -Eigen::Vector3d::UnitZ();  // under a shelf: upside down, still a rotation
  EXPECT_TRUE((p.transform().linear() * Eigen::Vector3d::UnitY()).isApprox(p.up, 1e-12));
  EXPECT_NEAR(p.transform().linear().determinant(), 1.0, 1e-12);
}

TEST(Placement, AddsTheModelAsVirtualMeshesStandingAtThePoint) {
  MrScene scene;
  scene.add_material({});
  add_virtual_model(scene, make_glossy_pebble(16), Placement::parse("0.3,-0.2,0.75"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_FALSE(scene.meshes[0].real);
  EXPECT_EQ(scene.meshes[0].triangle_material[0], 1u);
  float lowest = 10.f;
  for (const Eigen::Vector3f& p : scene.meshes[0].positions) lowest = std::min(lowest, p.z());
  EXPECT_NEAR(lowest, 0.75f, 1e-5f);
  scene.validate();
}

}  // namespace
}  // namespace relight::render
