#pragma once
// A texture of a virtual object's material (glTF 2.0 `baseColorTexture`, `emissiveTexture`,
// `metallicRoughnessTexture`, `normalTexture`): the factor its material's k_d (or emission) is
// multiplied by at a surface point, per channel, from the point's texture coordinates, or
// (metallic-roughness) the per-point parameters of the material's mapping to Phong (mr_scene.h),
// or (normal) the
// tangent-space normal (normal_map.h).
//
// Texels are kept as the file has them, 8 bits per channel: sRGB-encoded (glTF's base colour and
// emission) or linear (glTF's metallic-roughness and normal data, TextureEncoding::Linear), with a
// mip chain made in linear RGB (each level a 2x2 box filter of the one above, re-encoded), so
// that the CPU renderers and the Vulkan shading sample the same packed words (dir_texture.glsl
// is this file's GLSL twin). A sample is trilinear: bilinear within the two levels around `lod`,
// linear between them, each texel decoded to linear RGB before filtering (filtering the encoded
// values would darken edges between colours). lod = log2 of the pixel footprint in level-0 texels
// (0: magnified or one texel per pixel); the path tracer samples level 0 and lets its pixel
// samples average the texture, DIR's one sample per pixel takes the footprint from the G-buffer.
//
// A texture may carry KHR_texture_transform's affine map of the coordinates (UvTransform), applied
// before every sample; the footprint grows with its larger scale.
//
// Departures from glTF's sampler: the filters are always linear (a NEAREST magnification filter
// is read as LINEAR).
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "relight/core/image.h"

namespace relight::render {

enum class TextureWrap : std::uint32_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };
/// How a texel's 8-bit values map to [0, 1]: the sRGB curve (colours) or value / 255 (data).
enum class TextureEncoding : std::uint32_t { Srgb = 0, Linear = 1 };

/// uv' = linear uv + offset: glTF's KHR_texture_transform (offset, rotation, scale), i.e.
/// T(offset) R(rotation) S(scale). The rotation turns the coordinates counter-clockwise as drawn
/// with v down (u' = cos u + sin v, v' = -sin u + cos v): what Khronos' TextureTransformTest
/// sample and the common viewers show; the GLSL listing of the extension's README has the
/// opposite sign (KhronosGroup/glTF issue 1563).
struct UvTransform {
  Eigen::Matrix2f linear = Eigen::Matrix2f::Identity();
  Eigen::Vector2f offset = Eigen::Vector2f::Zero();

  [[nodiscard]] static UvTransform gltf(const Eigen::Vector2f& offset, float rotation, const Eigen::Vector2f& scale);
  [[nodiscard]] Eigen::Vector2f apply(const Eigen::Vector2f& uv) const { return linear * uv + offset; }
  /// The most the map lengthens a step: its larger singular value.
  [[nodiscard]] float stretch() const;
  [[nodiscard]] bool identity() const { return linear.isIdentity(0.f) && offset.isZero(0.f); }
};

/// sRGB-encoded 8-bit value -> linear and back (core/srgb.h's srgb8_to_linear and
/// encode_srgb8_channel), by the names the texture code uses.
[[nodiscard]] float srgb_to_linear(std::uint8_t value);
[[nodiscard]] std::uint8_t linear_to_srgb(float linear);

class Texture {
 public:
  /// Builds the mip chain from RGB texels encoded as `encoding` says; throws relight::Error when
  /// the image is empty.
  Texture(std::string name, const ColorImage& texels, TextureWrap wrap_u = TextureWrap::Repeat,
          TextureWrap wrap_v = TextureWrap::Repeat, TextureEncoding encoding = TextureEncoding::Srgb,
          UvTransform transform = {});

  /// Linear RGB at texture coordinates (u, v) (glTF's: (0, 0) is the image's top-left corner;
  /// before the transform) and mip level `lod` (clamped to the chain).
  [[nodiscard]] Eigen::Vector3f sample(float u, float v, float lod = 0.f) const;
  /// The texture's average colour (linear RGB): what a pixel covering all of it shows.
  [[nodiscard]] Eigen::Vector3f mean() const;
  /// The mip level for a pixel whose footprint spans `footprint` in texture coordinates (the
  /// longer of its two sides; before the transform): log2 of that in texels of the texture's
  /// longer side, in [0, top].
  /// Exact for square textures; on others the shorter axis is filtered a little more.
  [[nodiscard]] float level_of_detail(float footprint) const;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] int width() const { return widths_.front(); }
  [[nodiscard]] int height() const { return heights_.front(); }
  [[nodiscard]] int levels() const { return static_cast<int>(widths_.size()); }
  [[nodiscard]] int level_width(int level) const { return widths_[static_cast<std::size_t>(level)]; }
  [[nodiscard]] int level_height(int level) const { return heights_[static_cast<std::size_t>(level)]; }
  /// Index of level `level`'s first texel in texels().
  [[nodiscard]] std::size_t level_offset(int level) const { return offsets_[static_cast<std::size_t>(level)]; }
  /// Every level's texels, row by row, as r | g << 8 | b << 16 (encoded as encoding() says).
  [[nodiscard]] std::span<const std::uint32_t> texels() const { return texels_; }
  [[nodiscard]] TextureWrap wrap_u() const { return wrap_u_; }
  [[nodiscard]] TextureWrap wrap_v() const { return wrap_v_; }
  [[nodiscard]] TextureEncoding encoding() const { return encoding_; }
  [[nodiscard]] const UvTransform& transform() const { return transform_; }

 private:
  [[nodiscard]] Eigen::Vector3f bilinear(int level, float u, float v) const;
  [[nodiscard]] Eigen::Vector3f decode(std::uint32_t texel) const;
  [[nodiscard]] std::uint32_t encode(const Eigen::Vector3f& value) const;

  std::string name_;
  std::vector<std::uint32_t> texels_;
  std::vector<int> widths_, heights_;
  std::vector<std::size_t> offsets_;
  TextureWrap wrap_u_, wrap_v_;
  TextureEncoding encoding_;
  UvTransform transform_;
};

}  // namespace relight::render
