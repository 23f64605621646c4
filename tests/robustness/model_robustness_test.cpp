// Robustness matrix, virtual objects (--object): a missing, malformed or inconsistent glTF/OBJ file
// is one error line naming it, exit 1, before any frame is rendered (no composite.mp4).
#include <gtest/gtest.h>

#include "inputs.h"
#include "outcome_checks.h"

namespace relight::robustness {
namespace {

class ModelRobustness : public ::testing::Test {
 protected:
  // The model goes into the synthetic sequence (its table and probe give a placement and lights).
  RunOutcome replay_with(const std::filesystem::path& model) {
    return run_relight({"replay", "--quiet", synthetic_sequence().string(), "--object", model.string(), "--vpls", "8",
                        "--out", out.string()});
  }
  void expect_rejected(const std::filesystem::path& model, const std::string& reason) {
    SCOPED_TRACE(model.filename().string());
    const auto run = replay_with(model);
    expect_clean_error(run, 1, model.string() + ": ", out);
    EXPECT_NE(run.err.find(reason), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(out / "composite.mp4"));
    expect_bounded_memory(run);  // e.g. a glTF claiming 2^31 vertices allocates nothing for them
  }
  std::filesystem::path write(const std::string& name, std::string_view text) {
    write_file_atomically(dir.path() / name, text);
    return dir.path() / name;
  }
  test::TempDir dir;
  const std::filesystem::path out = dir.path() / "out";
};

TEST_F(ModelRobustness, MissingFile) {
  expect_rejected(dir.path() / "no_such_model.glb", "no such model file");
}

TEST_F(ModelRobustness, TruncatedGltf) {
  const std::string pebble = read_text_file(kData / "models" / "glossy_pebble.gltf");
  const auto model = write("pebble.gltf", std::string_view(pebble).substr(0, pebble.size() / 2));
  const auto run = replay_with(model);
  expect_clean_error(run, 1, model.string() + ": cannot read glTF", out);
  EXPECT_LT(run.err.size(), 400u) << "a short line, not the file's contents";
}

TEST_F(ModelRobustness, GarbageGlb) {
  expect_rejected(write("garbage.glb", "glTF\x02\x00\x00\x00 not really a binary glTF"), "cannot read glTF");
}

TEST_F(ModelRobustness, GltfIndexPastItsVertices) {
  // One triangle whose third index (7) points past the 3 vertices.
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAcAAAA="}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
  expect_rejected(write("bad_index.gltf", gltf), "vertex 7");
}

TEST_F(ModelRobustness, GltfMaterialThatDoesNotExist) {
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 4}]}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})";
  expect_rejected(write("bad_material.gltf", gltf), "material 4");
}

TEST_F(ModelRobustness, EmptyObj) { expect_rejected(write("empty.obj", ""), "no triangles"); }

TEST_F(ModelRobustness, ObjFaceIndexPastItsVertices) {
  expect_rejected(write("bad_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"), "vertex 7");
}

TEST_F(ModelRobustness, ObjNormalIndexPastItsNormals) {
  expect_rejected(write("bad_normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//5 3//1\n"), "normal 5");
}

TEST_F(ModelRobustness, GltfWithNonFiniteVertex) {
  // The second vertex's z is NaN.
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAMB/AAAAAAAAgD8AAAAA"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})";
  expect_rejected(write("nan.gltf", gltf), "not finite");
}

TEST_F(ModelRobustness, GltfClaimingHugeVertexCounts) {
  // 3 vertices in the buffer; the accessor claims 2^31 of them, or a count whose size in bytes
  // wraps around 2^64 to 20 bytes (which once passed the check and read far past the buffer).
  for (const std::string count : {"2147483648", "1537228672809129303"}) {
    const std::string gltf =
        R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": )" +
        count + R"(, "type": "VEC3"}]})";
    expect_rejected(write("huge_" + count + ".gltf", gltf), "past the end of its buffer");
  }
}

}  // namespace
}  // namespace relight::robustness
