// glTF 2.0 reading and writing (tinygltf).
#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <map>
#include <optional>
#include <span>
#include <sstream>
#include <tuple>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/render/scene/model_io.h"

namespace relight::render {
namespace {

using tinygltf::Value;

float number(const Value& object, const char* key, float fallback) {
  return object.Has(key) && object.Get(key).IsNumber() ? static_cast<float>(object.Get(key).GetNumberAsDouble())
                                                       : fallback;
}

/// A texture reference's KHR_texture_transform object, or null without one.
template <typename Info>
const Value* texture_transform_of(const Info& info) {
  const auto found = info.extensions.find("KHR_texture_transform");
  return found != info.extensions.end() && found->second.IsObject() ? &found->second : nullptr;
}

/// A texture reference's KHR_texture_transform (identity without one).
template <typename Info>
UvTransform uv_transform(const Info& info) {
  const Value* transform = texture_transform_of(info);
  if (!transform) return {};
  const Value& t = *transform;
  const auto pair = [&t](const char* key, Eigen::Vector2f fallback) {
    if (!t.Has(key) || !t.Get(key).IsArray() || t.Get(key).ArrayLen() != 2) return fallback;
    for (int i = 0; i < 2; ++i)
      if (t.Get(key).Get(i).IsNumber()) fallback[i] = static_cast<float>(t.Get(key).Get(i).GetNumberAsDouble());
    return fallback;
  };
  return UvTransform::gltf(pair("offset", Eigen::Vector2f::Zero()), number(t, "rotation", 0.f),
                           pair("scale", Eigen::Vector2f::Ones()));
}

/// A texture reference's TEXCOORD set: the extension's texCoord overrides the reference's.
template <typename Info>
int texcoord_set_of(const Info& info) {
  const Value* transform = texture_transform_of(info);
  if (transform && transform->Has("texCoord") && transform->Get("texCoord").IsInt())
    return transform->Get("texCoord").GetNumberAsInt();
  return info.texCoord;
}

std::optional<PhongMaterial> phong_extras(const tinygltf::Material& m) {
  if (!m.extras.IsObject() || !m.extras.Has("relight_phong")) return std::nullopt;
  const Value& phong = m.extras.Get("relight_phong");
  PhongMaterial out;
  out.name = m.name;
  if (phong.Has("kd") && phong.Get("kd").IsArray() && phong.Get("kd").ArrayLen() == 3)
    for (int c = 0; c < 3; ++c) out.kd[c] = static_cast<float>(phong.Get("kd").Get(c).GetNumberAsDouble());
  out.ks = number(phong, "ks", 0.f);
  out.n = number(phong, "n", 1.f);
  return out;
}

const Value* extension_of(const tinygltf::Material& m, const char* name) {
  const auto found = m.extensions.find(name);
  return found != m.extensions.end() && found->second.IsObject() ? &found->second : nullptr;
}

/// An RGB array member of a glTF object, or `fallback`.
Eigen::Vector3f colour(const Value& object, const char* key, const Eigen::Vector3f& fallback) {
  if (!object.Has(key) || !object.Get(key).IsArray() || object.Get(key).ArrayLen() != 3) return fallback;
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(object.Get(key).Get(c).GetNumberAsDouble());
  return out;
}

/// The specular part of a glTF material (model_io.h): glass from KHR_materials_transmission
/// (with _ior and _volume), a mirror from a smooth untextured metal.
SpecularMaterial specular_of(const tinygltf::Material& m, const Eigen::Vector3f& base) {
  const auto& pbr = m.pbrMetallicRoughness;
  if (const Value* transmission = extension_of(m, "KHR_materials_transmission");
      transmission && number(*transmission, "transmissionFactor", 0.f) >= kGltfTransmissionThreshold) {
    SpecularMaterial glass = dielectric(1.5f);
    if (const Value* ior = extension_of(m, "KHR_materials_ior")) glass.ior = number(*ior, "ior", 1.5f);
    if (const Value* volume = extension_of(m, "KHR_materials_volume")) {
      glass.attenuation_color = colour(*volume, "attenuationColor", Eigen::Vector3f::Ones());
      glass.attenuation_distance = number(*volume, "attenuationDistance", std::numeric_limits<float>::infinity());
    }
    return glass;
  }
  if (pbr.metallicFactor >= kGltfMirrorMinMetallic && pbr.roughnessFactor <= kGltfMirrorMaxRoughness &&
      pbr.metallicRoughnessTexture.index < 0)
    return conductor(base);
  return {};
}

PhongMaterial from_gltf(const tinygltf::Material& m) {
  PhongMaterial out;
  const auto& pbr = m.pbrMetallicRoughness;
  const Eigen::Vector3f base(static_cast<float>(pbr.baseColorFactor[0]), static_cast<float>(pbr.baseColorFactor[1]),
                             static_cast<float>(pbr.baseColorFactor[2]));
  if (const auto phong = phong_extras(m)) {
    out = *phong;
  } else {
    out.metallic_roughness = {base, static_cast<float>(pbr.metallicFactor), static_cast<float>(pbr.roughnessFactor)};
    static_cast<Phong&>(out) = phong_from_metallic_roughness(out.metallic_roughness);
    out.name = m.name;
  }
  float strength = 1.f;
  if (const auto found = m.extensions.find("KHR_materials_emissive_strength"); found != m.extensions.end())
    strength = number(found->second, "emissiveStrength", 1.f);
  if (m.emissiveFactor.size() == 3)
    for (int c = 0; c < 3; ++c) out.emission[c] = static_cast<float>(m.emissiveFactor[static_cast<std::size_t>(c)]) * strength;
  out.specular = specular_of(m, base);
  if (out.specular.kind == SpecularKind::Dielectric && !phong_extras(m)) {
    // The Phong fallback of renderers without specular materials: a clear, glossy surface (the
    // metallic-roughness mapping would make clear glass of base colour white a white plaster).
    out.kd = base * (1.f - number(*extension_of(m, "KHR_materials_transmission"), "transmissionFactor", 0.f));
  }
  return out;
}

class AccessorReader {
 public:
  AccessorReader(const tinygltf::Model& model, int index, const std::string& file) : file_(file) {
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) fail("an accessor index is out of range");
    accessor_ = &model.accessors[static_cast<std::size_t>(index)];
    if (accessor_->sparse.isSparse) fail("sparse accessors are not supported");
    if (accessor_->bufferView < 0 || static_cast<std::size_t>(accessor_->bufferView) >= model.bufferViews.size())
      fail("an accessor has no buffer view");
    const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(accessor_->bufferView)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size()) fail("a buffer view has no buffer");
    const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(view.buffer)].data;
    const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor_->type));
    const int component_size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(accessor_->componentType));
    if (components <= 0 || component_size <= 0) fail("an accessor has an unknown type");
    element_size_ = static_cast<std::size_t>(components * component_size);
    stride_ = view.byteStride != 0 ? view.byteStride : element_size_;
    // Checked without a product that can wrap around: a file may claim any count or offset (a
    // count near 2^64 / stride made (count - 1) * stride small, and the reader then ran far
    // past the buffer), and the count is what the mesh's arrays are sized by.
    if (view.byteOffset > data.size()) fail("a buffer view starts past the end of its buffer");
    const std::size_t view_end =
        view.byteOffset + std::min<std::size_t>(view.byteLength, data.size() - view.byteOffset);
    if (accessor_->byteOffset > view_end - view.byteOffset) fail("an accessor reaches past the end of its buffer");
    const std::size_t begin = view.byteOffset + accessor_->byteOffset;
    const std::size_t room = view_end - begin;
    if (accessor_->count != 0 && (room < element_size_ || accessor_->count - 1 > (room - element_size_) / stride_))
      fail("an accessor reaches past the end of its buffer (" + std::to_string(accessor_->count) + " elements in " +
           std::to_string(room) + " bytes)");
    bytes_ = data.data() + begin;
  }

  [[nodiscard]] std::size_t count() const { return accessor_->count; }

  [[nodiscard]] Eigen::Vector3f vec3(std::size_t i) const {
    if (accessor_->type != TINYGLTF_TYPE_VEC3 || accessor_->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail("positions and normals must be float VEC3");
    float v[3];
    std::memcpy(v, bytes_ + i * stride_, sizeof v);
    return {v[0], v[1], v[2]};
  }

  /// A texture coordinate: float VEC2, or normalised unsigned byte or short VEC2 (glTF 3.7.2.1).
  [[nodiscard]] Eigen::Vector2f vec2(std::size_t i) const {
    if (accessor_->type != TINYGLTF_TYPE_VEC2) fail("texture coordinates must be VEC2");
    const unsigned char* p = bytes_ + i * stride_;
    switch (accessor_->componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v[2];
        std::memcpy(v, p, sizeof v);
        return {v[0], v[1]};
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        if (accessor_->normalized) return {float(p[0]) / 255.f, float(p[1]) / 255.f};
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        if (accessor_->normalized) {
          std::uint16_t v[2];
          std::memcpy(v, p, sizeof v);
          return {float(v[0]) / 65535.f, float(v[1]) / 65535.f};
        }
        break;
      default: break;
    }
    fail("texture coordinates must be float or normalised unsigned byte/short");
  }

  [[nodiscard]] std::uint32_t index(std::size_t i) const {
    const unsigned char* p = bytes_ + i * stride_;
    switch (accessor_->componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, sizeof v);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        std::uint32_t v;
        std::memcpy(&v, p, sizeof v);
        return v;
      }
      default: fail("indices must be unsigned integers");
    }
  }

 private:
  [[noreturn]] void fail(const std::string& why) const { throw Error(file_ + ": " + why); }

  std::string file_;
  const tinygltf::Accessor* accessor_ = nullptr;
  const unsigned char* bytes_ = nullptr;
  std::size_t element_size_ = 0;
  std::size_t stride_ = 0;
};

Eigen::Affine3f node_transform(const tinygltf::Node& node) {
  Eigen::Affine3f t = Eigen::Affine3f::Identity();
  if (node.matrix.size() == 16) {
    Eigen::Matrix4f m;
    for (int i = 0; i < 16; ++i) m(i % 4, i / 4) = static_cast<float>(node.matrix[static_cast<std::size_t>(i)]);
    t.matrix() = m;
    return t;
  }
  if (node.translation.size() == 3)
    t.translate(Eigen::Vector3f(static_cast<float>(node.translation[0]), static_cast<float>(node.translation[1]),
                                static_cast<float>(node.translation[2])));
  if (node.rotation.size() == 4)
    t.rotate(Eigen::Quaternionf(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                                static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]))
                 .normalized());
  if (node.scale.size() == 3)
    t.scale(Eigen::Vector3f(static_cast<float>(node.scale[0]), static_cast<float>(node.scale[1]),
                            static_cast<float>(node.scale[2])));
  return t;
}

class GltfMeshCollector {
 public:
  GltfMeshCollector(const tinygltf::Model& gltf, VirtualModel& out, std::string file, std::uint32_t default_material)
      : gltf_(gltf), out_(out), file_(std::move(file)), default_material_(default_material) {}

  void visit(int node_index, const Eigen::Affine3f& parent, int depth) {
    if (node_index < 0 || static_cast<std::size_t>(node_index) >= gltf_.nodes.size() || depth > 64)
      throw Error(file_ + ": a node index is out of range or the node tree is cyclic");
    const tinygltf::Node& node = gltf_.nodes[static_cast<std::size_t>(node_index)];
    const Eigen::Affine3f transform = parent * node_transform(node);
    if (node.mesh >= 0) add_mesh(node.mesh, transform);
    for (int child : node.children) visit(child, transform, depth + 1);
  }

 private:
  void add_mesh(int mesh_index, const Eigen::Affine3f& transform) {
    if (static_cast<std::size_t>(mesh_index) >= gltf_.meshes.size()) throw Error(file_ + ": a mesh index is out of range");
    const tinygltf::Mesh& source = gltf_.meshes[static_cast<std::size_t>(mesh_index)];
    for (const tinygltf::Primitive& primitive : source.primitives) {
      if (primitive.mode != -1 && primitive.mode != TINYGLTF_MODE_TRIANGLES)
        throw Error(file_ + ": only triangle primitives are supported");
      out_.meshes.push_back(primitive_mesh(source.name, primitive, transform));
    }
  }

  TriangleMesh primitive_mesh(const std::string& name, const tinygltf::Primitive& primitive,
                              const Eigen::Affine3f& transform) const {
    const auto position = primitive.attributes.find("POSITION");
    if (position == primitive.attributes.end()) throw Error(file_ + ": a primitive has no POSITION");
    TriangleMesh mesh;
    mesh.name = name;
    const AccessorReader positions(gltf_, position->second, file_);
    for (std::size_t i = 0; i < positions.count(); ++i) mesh.positions.push_back(transform * positions.vec3(i));
    if (const auto normal = primitive.attributes.find("NORMAL"); normal != primitive.attributes.end()) {
      const AccessorReader normals(gltf_, normal->second, file_);
      const Eigen::Matrix3f normal_matrix = transform.linear().inverse().transpose();
      for (std::size_t i = 0; i < normals.count(); ++i) mesh.normals.push_back((normal_matrix * normals.vec3(i)).normalized());
    }
    if (const std::optional<int> set = texcoord_set(primitive.material, name)) {
      const std::string attribute = "TEXCOORD_" + std::to_string(*set);
      const auto found = primitive.attributes.find(attribute);
      if (found == primitive.attributes.end())
        throw Error(file_ + ": mesh '" + name + "' has a textured material but no " + attribute);
      const AccessorReader texcoords(gltf_, found->second, file_);
      if (texcoords.count() != mesh.positions.size())
        throw Error(file_ + ": mesh '" + name + "' has " + std::to_string(texcoords.count()) + " " + attribute +
                    " for " + std::to_string(mesh.positions.size()) + " vertices");
      for (std::size_t i = 0; i < texcoords.count(); ++i) mesh.texcoords.push_back(texcoords.vec2(i));
    }
    std::vector<std::uint32_t> indices;
    if (primitive.indices >= 0) {
      const AccessorReader reader(gltf_, primitive.indices, file_);
      for (std::size_t i = 0; i < reader.count(); ++i) {
        indices.push_back(reader.index(i));
        if (indices.back() >= mesh.positions.size())
          throw Error(file_ + ": a primitive refers to vertex " + std::to_string(indices.back()) + ", but it has " +
                      std::to_string(mesh.positions.size()));
      }
    } else {
      for (std::size_t i = 0; i < mesh.positions.size(); ++i) indices.push_back(static_cast<std::uint32_t>(i));
    }
    if (primitive.material >= 0 && static_cast<std::size_t>(primitive.material) >= gltf_.materials.size())
      throw Error(file_ + ": a primitive uses material " + std::to_string(primitive.material) + ", but the file has " +
                  std::to_string(gltf_.materials.size()));
    const std::uint32_t material = primitive.material >= 0 ? static_cast<std::uint32_t>(primitive.material) : default_material_;
    for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
      mesh.triangles.push_back({indices[i], indices[i + 1], indices[i + 2]});
      mesh.triangle_material.push_back(material);
    }
    if (mesh.normals.size() != mesh.positions.size()) compute_vertex_normals(mesh);
    return mesh;
  }

  /// The TEXCOORD set a primitive's textured material reads (nullopt: no texture); one set per
  /// material, since relight's meshes carry one.
  std::optional<int> texcoord_set(int material, const std::string& mesh) const {
    if (material < 0 || static_cast<std::size_t>(material) >= gltf_.materials.size()) return std::nullopt;
    const PhongMaterial& ours = out_.materials[static_cast<std::size_t>(material)];
    const tinygltf::Material& theirs = gltf_.materials[static_cast<std::size_t>(material)];
    const std::array<std::pair<bool, int>, 4> sets{
        {{ours.base_color != nullptr, texcoord_set_of(theirs.pbrMetallicRoughness.baseColorTexture)},
         {ours.emission_texture != nullptr, texcoord_set_of(theirs.emissiveTexture)},
         {ours.metallic_roughness_texture != nullptr,
          texcoord_set_of(theirs.pbrMetallicRoughness.metallicRoughnessTexture)},
         {ours.normal_texture != nullptr, texcoord_set_of(theirs.normalTexture)}}};
    std::optional<int> out;
    for (const auto& [used, set] : sets) {
      if (!used) continue;
      if (out && *out != set)
        throw Error(file_ + ": mesh '" + mesh + "': the material's textures use different TEXCOORD sets (" +
                    std::to_string(*out) + ", " + std::to_string(set) + "); relight reads one");
      out = set;
    }
    return out;
  }

  const tinygltf::Model& gltf_;
  VirtualModel& out_;
  std::string file_;
  std::uint32_t default_material_;
};

// tinygltf's JSON errors quote what was last read, which can be a whole base64 buffer.
std::string first_line(std::string text) {
  text = text.substr(0, text.find('\n'));
  while (!text.empty() && (text.back() == '\r' || text.back() == ' ')) text.pop_back();
  constexpr std::size_t kLongest = 200;
  if (text.size() > kLongest) text = text.substr(0, kLongest) + "...";
  return text;
}

/// The encoded bytes of every image that tinygltf read from a data URI or an external file,
/// by image index; images in a buffer view are read from the buffer after loading. Nothing is
/// decoded while loading: only the images that a material's base colour uses are (textures()),
/// so an unused broken or hostile image cannot fail or slow down reading the model.
struct EncodedImages {
  std::vector<std::vector<std::uint8_t>> bytes;
};

bool keep_encoded_image(tinygltf::Image* image, int index, std::string*, std::string*, int, int,
                        const unsigned char* bytes, int size, void* user) {
  if (index < 0 || image->bufferView >= 0 || size <= 0) return true;
  auto& images = *static_cast<EncodedImages*>(user);
  if (images.bytes.size() <= static_cast<std::size_t>(index)) images.bytes.resize(static_cast<std::size_t>(index) + 1);
  images.bytes[static_cast<std::size_t>(index)].assign(bytes, bytes + size);
  return true;
}

/// Larger textures are refused (8192^2 texels with their mip chain take 360 MB), and so are
/// models whose decoded textures would hold more texels than that together.
constexpr int kMaxTextureSide = 8192;
constexpr std::size_t kMaxTextureTexels = std::size_t{kMaxTextureSide} * kMaxTextureSide;

TextureWrap wrap_of(int gl_wrap) {
  switch (gl_wrap) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::MirroredRepeat;
    default: return TextureWrap::Repeat;
  }
}

/// The textures of a model's materials, each (image, sampler, encoding) decoded once.
class GltfTextures {
 public:
  GltfTextures(const tinygltf::Model& gltf, const EncodedImages& images, std::string file)
      : gltf_(gltf), images_(images), file_(std::move(file)) {}

  /// The texture a material refers to with `info` (its base colour's, emission's, metallic-
  /// roughness's or normal's, whose texels are `encoding`; with its KHR_texture_transform), or
  /// null for index -1.
  template <typename Info>
  std::shared_ptr<const Texture> texture(const tinygltf::Material& material, const Info& info,
                                         TextureEncoding encoding = TextureEncoding::Srgb) {
    const int index = info.index;
    if (index < 0) return nullptr;
    if (static_cast<std::size_t>(index) >= gltf_.textures.size())
      fail("material '" + material.name + "' uses texture " + std::to_string(index) + ", but the file has " +
           std::to_string(gltf_.textures.size()));
    const tinygltf::Texture& texture = gltf_.textures[static_cast<std::size_t>(index)];
    if (texture.source < 0 || static_cast<std::size_t>(texture.source) >= gltf_.images.size())
      fail("texture " + std::to_string(index) + " has no image");
    if (texture.sampler >= 0 && static_cast<std::size_t>(texture.sampler) >= gltf_.samplers.size())
      fail("texture " + std::to_string(index) + " uses a missing sampler");
    const UvTransform transform = uv_transform(info);
    if (!transform.linear.allFinite() || !transform.offset.allFinite())
      fail("texture " + std::to_string(index) + " has a non-finite KHR_texture_transform");
    const std::tuple key{texture.source, texture.sampler, encoding,
                         std::array<float, 6>{transform.linear(0, 0), transform.linear(0, 1), transform.linear(1, 0),
                                              transform.linear(1, 1), transform.offset.x(), transform.offset.y()}};
    if (const auto found = decoded_.find(key); found != decoded_.end()) return found->second;
    const tinygltf::Image& image = gltf_.images[static_cast<std::size_t>(texture.source)];
    const std::string what = file_ + ": image " + std::to_string(texture.source) +
                             (image.uri.empty() || image.uri.starts_with("data:") ? "" : " (" + image.uri + ")");
    const ColorImage decoded = decode_color(encoded(image, texture.source, what), what, kMaxTextureSide);
    texels_ += decoded.size();
    if (texels_ > kMaxTextureTexels)
      fail("its textures hold more than " + std::to_string(kMaxTextureTexels) +
           " texels together (the limit), at image " + std::to_string(texture.source));
    TextureWrap wrap_u = TextureWrap::Repeat, wrap_v = TextureWrap::Repeat;
    if (texture.sampler >= 0) {
      const tinygltf::Sampler& sampler = gltf_.samplers[static_cast<std::size_t>(texture.sampler)];
      wrap_u = wrap_of(sampler.wrapS);
      wrap_v = wrap_of(sampler.wrapT);
    }
    auto out =
        std::make_shared<const Texture>(image.name.empty() ? "image " + std::to_string(texture.source) : image.name,
                                        decoded, wrap_u, wrap_v, encoding, transform);
    decoded_.emplace(key, out);
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const { throw Error(file_ + ": " + why); }

  std::span<const std::uint8_t> encoded(const tinygltf::Image& image, int index, const std::string& what) const {
    if (image.bufferView >= 0) {
      if (static_cast<std::size_t>(image.bufferView) >= gltf_.bufferViews.size())
        fail("an image's buffer view is missing");
      const tinygltf::BufferView& view = gltf_.bufferViews[static_cast<std::size_t>(image.bufferView)];
      if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= gltf_.buffers.size())
        fail("a buffer view has no buffer");
      const std::vector<unsigned char>& data = gltf_.buffers[static_cast<std::size_t>(view.buffer)].data;
      if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
        throw Error(what + ": its buffer view reaches past the end of its buffer");
      return {data.data() + view.byteOffset, view.byteLength};
    }
    if (static_cast<std::size_t>(index) >= images_.bytes.size() ||
        images_.bytes[static_cast<std::size_t>(index)].empty())
      throw Error(what + ": cannot read the image (missing file or empty data)");
    return images_.bytes[static_cast<std::size_t>(index)];
  }

  const tinygltf::Model& gltf_;
  const EncodedImages& images_;
  std::string file_;
  std::map<std::tuple<int, int, TextureEncoding, std::array<float, 6>>, std::shared_ptr<const Texture>> decoded_;
  std::size_t texels_ = 0;  // decoded so far
};

tinygltf::Model read_gltf(const std::filesystem::path& path, bool binary, EncodedImages& images) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_encoded_image, &images);
  tinygltf::Model gltf;
  std::string error, warning;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromFile(&gltf, &error, &warning, path.string())
                : loader.LoadASCIIFromFile(&gltf, &error, &warning, path.string());
  } catch (const std::exception& e) {
    // tinygltf 2.7 indexes with vector::at() in places where it does not check sizes first
    // (a GLB buffer of byteLength 0, an empty embedded image): a malformed file, not a bug here.
    error = e.what();
  }
  if (!ok) throw Error(path.string() + ": cannot read glTF: " + (error.empty() ? "unknown error" : first_line(error)));
  return gltf;
}

}  // namespace

VirtualModel load_gltf(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  EncodedImages images;
  const tinygltf::Model gltf = read_gltf(path, extension == ".glb", images);
  VirtualModel model;
  model.name = path.stem().string();
  GltfTextures textures(gltf, images, path.string());
  for (const tinygltf::Material& m : gltf.materials) {
    model.materials.push_back(from_gltf(m));
    model.materials.back().base_color = textures.texture(m, m.pbrMetallicRoughness.baseColorTexture);
    model.materials.back().emission_texture = textures.texture(m, m.emissiveTexture);
    // relight's own Phong parameters (extras) are taken as they are, without the metallic-
    // roughness mapping the texture would feed.
    if (!phong_extras(m))
      model.materials.back().metallic_roughness_texture =
          textures.texture(m, m.pbrMetallicRoughness.metallicRoughnessTexture, TextureEncoding::Linear);
    model.materials.back().normal_texture = textures.texture(m, m.normalTexture, TextureEncoding::Linear);
    model.materials.back().normal_scale = static_cast<float>(m.normalTexture.scale);
  }
  const auto default_material = static_cast<std::uint32_t>(model.materials.size());
  model.materials.push_back(PhongMaterial{{{0.8f, 0.8f, 0.8f}, 0.f, 1.f}, "default", {0.f, 0.f, 0.f}});
  GltfMeshCollector collector(gltf, model, path.string(), default_material);
  const int scene = gltf.defaultScene >= 0 ? gltf.defaultScene : 0;
  if (static_cast<std::size_t>(scene) < gltf.scenes.size()) {
    for (int node : gltf.scenes[static_cast<std::size_t>(scene)].nodes) collector.visit(node, Eigen::Affine3f::Identity(), 0);
  }
  std::erase_if(model.meshes, [](const TriangleMesh& m) { return m.triangles.empty(); });
  if (model.meshes.empty()) throw Error(path.string() + ": the glTF file holds no triangles");
  check_model(model, path);
  for (const std::string& name : gltf.extensionsUsed)
    if (std::find(kSupportedGltfExtensions.begin(), kSupportedGltfExtensions.end(), name) ==
        kSupportedGltfExtensions.end())
      model.warnings.push_back("glTF extension " + name + " is not supported: ignored");
  return model;
}

namespace {

/// Appends raw bytes to the buffer and returns the new buffer view's index.
int add_view(tinygltf::Model& gltf, const void* bytes, std::size_t size, int target) {
  std::vector<unsigned char>& data = gltf.buffers[0].data;
  while (data.size() % 4 != 0) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* begin = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), begin, begin + size);
  gltf.bufferViews.push_back(view);
  return static_cast<int>(gltf.bufferViews.size() - 1);
}

int add_vec3_accessor(tinygltf::Model& gltf, const std::vector<Eigen::Vector3f>& values, bool with_bounds) {
  std::vector<float> flat;
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : values) {
    flat.insert(flat.end(), {v.x(), v.y(), v.z()});
    box.extend(v);
  }
  tinygltf::Accessor accessor;
  accessor.bufferView = add_view(gltf, flat.data(), flat.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.type = TINYGLTF_TYPE_VEC3;
  accessor.count = values.size();
  if (with_bounds) {  // required for POSITION by the specification
    accessor.minValues = {box.min().x(), box.min().y(), box.min().z()};
    accessor.maxValues = {box.max().x(), box.max().y(), box.max().z()};
  }
  gltf.accessors.push_back(accessor);
  return static_cast<int>(gltf.accessors.size() - 1);
}

int add_index_accessor(tinygltf::Model& gltf, const std::vector<std::uint32_t>& indices) {
  tinygltf::Accessor accessor;
  accessor.bufferView =
      add_view(gltf, indices.data(), indices.size() * sizeof(std::uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  accessor.type = TINYGLTF_TYPE_SCALAR;
  accessor.count = indices.size();
  gltf.accessors.push_back(accessor);
  return static_cast<int>(gltf.accessors.size() - 1);
}

tinygltf::Material to_gltf(const PhongMaterial& m) {
  tinygltf::Material out;
  out.name = m.name;
  out.pbrMetallicRoughness.baseColorFactor = {m.kd.x(), m.kd.y(), m.kd.z(), 1.0};
  out.pbrMetallicRoughness.metallicFactor = 0.0;
  // Inverse of the exponent mapping in model_io.h, so that other viewers show a similar gloss.
  out.pbrMetallicRoughness.roughnessFactor = std::sqrt(std::sqrt(2.0 / (m.n + 2.0)));
  const float peak = m.emission.maxCoeff();
  if (peak > 0.f) {
    const Eigen::Vector3f factor = m.emission / std::max(1.f, peak);
    out.emissiveFactor = {factor.x(), factor.y(), factor.z()};
    if (peak > 1.f) {
      tinygltf::Value::Object strength{{"emissiveStrength", tinygltf::Value(static_cast<double>(peak))}};
      out.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(strength);
    }
  }
  tinygltf::Value::Array kd{tinygltf::Value(static_cast<double>(m.kd.x())), tinygltf::Value(static_cast<double>(m.kd.y())),
                            tinygltf::Value(static_cast<double>(m.kd.z()))};
  tinygltf::Value::Object phong{{"kd", tinygltf::Value(kd)},
                                {"ks", tinygltf::Value(static_cast<double>(m.ks))},
                                {"n", tinygltf::Value(static_cast<double>(m.n))}};
  out.extras = tinygltf::Value(tinygltf::Value::Object{{"relight_phong", tinygltf::Value(phong)}});
  const auto rgb = [](const Eigen::Vector3f& c) {
    return tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(static_cast<double>(c.x())),
                                                  tinygltf::Value(static_cast<double>(c.y())),
                                                  tinygltf::Value(static_cast<double>(c.z()))});
  };
  const SpecularMaterial& s = m.specular;
  if (s.kind == SpecularKind::Conductor) {
    out.pbrMetallicRoughness.baseColorFactor = {s.reflectance.x(), s.reflectance.y(), s.reflectance.z(), 1.0};
    out.pbrMetallicRoughness.metallicFactor = 1.0;
    out.pbrMetallicRoughness.roughnessFactor = 0.0;
  } else if (s.kind == SpecularKind::Dielectric) {
    out.pbrMetallicRoughness.roughnessFactor = 0.0;
    out.extensions["KHR_materials_transmission"] =
        tinygltf::Value(tinygltf::Value::Object{{"transmissionFactor", tinygltf::Value(1.0)}});
    out.extensions["KHR_materials_ior"] =
        tinygltf::Value(tinygltf::Value::Object{{"ior", tinygltf::Value(static_cast<double>(s.ior))}});
    tinygltf::Value::Object volume{{"attenuationColor", rgb(s.attenuation_color)}};
    if (std::isfinite(s.attenuation_distance))
      volume["attenuationDistance"] = tinygltf::Value(static_cast<double>(s.attenuation_distance));
    out.extensions["KHR_materials_volume"] = tinygltf::Value(volume);
  }
  return out;
}

}  // namespace

void save_gltf(const std::filesystem::path& path, const VirtualModel& model) {
  tinygltf::Model gltf;
  gltf.asset.version = "2.0";
  gltf.asset.generator = "relight";
  gltf.buffers.resize(1);
  for (const PhongMaterial& m : model.materials) gltf.materials.push_back(to_gltf(m));
  if (std::any_of(model.materials.begin(), model.materials.end(), [](const PhongMaterial& m) { return m.emission.maxCoeff() > 1.f; }))
    gltf.extensionsUsed.push_back("KHR_materials_emissive_strength");
  if (std::any_of(model.materials.begin(), model.materials.end(),
                  [](const PhongMaterial& m) { return m.specular.kind == SpecularKind::Dielectric; }))
    for (const char* name : {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"})
      gltf.extensionsUsed.emplace_back(name);
  tinygltf::Scene scene;
  for (const TriangleMesh& source : model.meshes) {
    tinygltf::Mesh mesh;
    mesh.name = source.name;
    const int positions = add_vec3_accessor(gltf, source.positions, true);
    const int normals = source.normals.empty() ? -1 : add_vec3_accessor(gltf, source.normals, false);
    // One primitive per material.
    std::vector<std::uint32_t> materials = source.triangle_material;
    std::sort(materials.begin(), materials.end());
    materials.erase(std::unique(materials.begin(), materials.end()), materials.end());
    for (std::uint32_t material : materials) {
      std::vector<std::uint32_t> indices;
      for (std::size_t t = 0; t < source.triangles.size(); ++t)
        if (source.triangle_material[t] == material) indices.insert(indices.end(), source.triangles[t].begin(), source.triangles[t].end());
      tinygltf::Primitive primitive;
      primitive.attributes["POSITION"] = positions;
      if (normals >= 0) primitive.attributes["NORMAL"] = normals;
      primitive.indices = add_index_accessor(gltf, indices);
      primitive.material = static_cast<int>(material);
      primitive.mode = TINYGLTF_MODE_TRIANGLES;
      mesh.primitives.push_back(primitive);
    }
    gltf.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = source.name;
    node.mesh = static_cast<int>(gltf.meshes.size() - 1);
    gltf.nodes.push_back(node);
    scene.nodes.push_back(static_cast<int>(gltf.nodes.size() - 1));
  }
  gltf.scenes.push_back(scene);
  gltf.defaultScene = 0;
  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&gltf, stream, true, false))
    throw Error(path.string() + ": cannot encode the glTF model");
  write_file_atomically(path, stream.str());
}

VirtualModel load_model(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(path.string() + ": no such model file");
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension == ".obj") return load_obj(path);
  if (extension == ".gltf" || extension == ".glb") return load_gltf(path);
  throw Error(path.string() + ": unknown model format (expected .obj, .gltf or .glb)");
}

}  // namespace relight::render
