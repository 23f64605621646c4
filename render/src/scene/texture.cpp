#include "relight/render/scene/texture.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "relight/core/error.h"
#include "relight/core/srgb.h"

namespace relight::render {
namespace {

std::uint8_t to_byte(float value) {
  return static_cast<std::uint8_t>(std::lround(255.f * std::clamp(value, 0.f, 1.f)));
}

/// Texel index along an axis of `size` texels for the integer coordinate `i` (any sign).
int wrapped(int i, int size, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::ClampToEdge: return std::clamp(i, 0, size - 1);
    case TextureWrap::MirroredRepeat: {
      const int period = 2 * size;
      const int m = ((i % period) + period) % period;
      return m < size ? m : period - 1 - m;
    }
    case TextureWrap::Repeat: break;
  }
  return ((i % size) + size) % size;
}

}  // namespace

float srgb_to_linear(std::uint8_t value) { return srgb8_to_linear(value); }

std::uint8_t linear_to_srgb(float linear) { return encode_srgb8_channel(linear); }

UvTransform UvTransform::gltf(const Eigen::Vector2f& offset, float rotation, const Eigen::Vector2f& scale) {
  const float c = std::cos(rotation), s = std::sin(rotation);
  UvTransform out;
  out.linear << c * scale.x(), s * scale.y(), -s * scale.x(), c * scale.y();
  out.offset = offset;
  return out;
}

float UvTransform::stretch() const {
  // The 2x2 singular values: s1^2 + s2^2 = |A|_F^2, s1 s2 = |det A|.
  const float frobenius = linear.squaredNorm();
  const float determinant = linear(0, 0) * linear(1, 1) - linear(0, 1) * linear(1, 0);
  const float root = std::sqrt(std::max(frobenius * frobenius - 4.f * determinant * determinant, 0.f));
  return std::sqrt(0.5f * (frobenius + root));
}

Texture::Texture(std::string name, const ColorImage& texels, TextureWrap wrap_u, TextureWrap wrap_v,
                 TextureEncoding encoding, UvTransform transform)
    : name_(std::move(name)), wrap_u_(wrap_u), wrap_v_(wrap_v), encoding_(encoding), transform_(std::move(transform)) {
  if (texels.width() <= 0 || texels.height() <= 0) throw Error("texture " + name_ + " is empty");
  widths_.push_back(texels.width());
  heights_.push_back(texels.height());
  offsets_.push_back(0);
  texels_.reserve(texels.size() * 4 / 3 + 1);
  for (const Rgb8& p : texels.pixels())
    texels_.push_back(std::uint32_t(p.r) | (std::uint32_t(p.g) << 8) | (std::uint32_t(p.b) << 16));
  // Each level halves (rounding down, at least 1) and averages the 2x2 texels above in linear
  // RGB; an odd row or column of the level above is folded into its last texel's neighbour.
  while (widths_.back() > 1 || heights_.back() > 1) {
    const int above_w = widths_.back(), above_h = heights_.back();
    const std::size_t above = offsets_.back();
    const int w = std::max(1, above_w / 2), h = std::max(1, above_h / 2);
    offsets_.push_back(texels_.size());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int x1 = x + 1 == w ? above_w : std::min(2 * x + 2, above_w);
        const int y1 = y + 1 == h ? above_h : std::min(2 * y + 2, above_h);
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int v = 2 * y; v < y1; ++v)
          for (int u = 2 * x; u < x1; ++u)
            sum += decode(texels_[above + static_cast<std::size_t>(v) * static_cast<std::size_t>(above_w) +
                                  static_cast<std::size_t>(u)]);
        texels_.push_back(encode(sum / static_cast<float>((x1 - 2 * x) * (y1 - 2 * y))));
      }
    widths_.push_back(w);
    heights_.push_back(h);
  }
}

Eigen::Vector3f Texture::bilinear(int level, float u, float v) const {
  const int w = level_width(level), h = level_height(level);
  const float x = u * static_cast<float>(w) - 0.5f, y = v * static_cast<float>(h) - 0.5f;
  const float fx0 = std::floor(x), fy0 = std::floor(y);
  const float fx = x - fx0, fy = y - fy0;
  // Coordinates far outside [0, 1] keep their fraction; the integer part only selects a period.
  const auto x0 = static_cast<int>(std::fmod(fx0, 2.f * static_cast<float>(w) * 1024.f));
  const auto y0 = static_cast<int>(std::fmod(fy0, 2.f * static_cast<float>(h) * 1024.f));
  const std::uint32_t* base = texels_.data() + level_offset(level);
  const auto at = [&](int i, int j) {
    return decode(base[static_cast<std::size_t>(wrapped(j, h, wrap_v_)) * static_cast<std::size_t>(w) +
                       static_cast<std::size_t>(wrapped(i, w, wrap_u_))]);
  };
  return (1.f - fy) * ((1.f - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1.f - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

Eigen::Vector3f Texture::sample(float u_in, float v_in, float lod) const {
  const Eigen::Vector2f uv = transform_.apply({u_in, v_in});
  const float u = uv.x(), v = uv.y();
  if (!std::isfinite(u) || !std::isfinite(v)) return mean();
  const float level = std::clamp(std::isfinite(lod) ? lod : 0.f, 0.f, static_cast<float>(levels() - 1));
  const int l0 = static_cast<int>(level);
  const float f = level - static_cast<float>(l0);
  Eigen::Vector3f near = bilinear(l0, u, v);
  if (f == 0.f || l0 + 1 >= levels()) return near;
  return (1.f - f) * near + f * bilinear(l0 + 1, u, v);
}

Eigen::Vector3f Texture::mean() const { return decode(texels_.back()); }

Eigen::Vector3f Texture::decode(std::uint32_t texel) const {
  if (encoding_ == TextureEncoding::Linear)
    return Eigen::Vector3f(static_cast<float>(texel & 0xffu), static_cast<float>((texel >> 8) & 0xffu),
                           static_cast<float>((texel >> 16) & 0xffu)) /
           255.f;
  return {srgb8_to_linear(static_cast<std::uint8_t>(texel & 0xffu)),
          srgb8_to_linear(static_cast<std::uint8_t>((texel >> 8) & 0xffu)),
          srgb8_to_linear(static_cast<std::uint8_t>((texel >> 16) & 0xffu))};
}

std::uint32_t Texture::encode(const Eigen::Vector3f& value) const {
  if (encoding_ == TextureEncoding::Linear)
    return std::uint32_t(to_byte(value.x())) | (std::uint32_t(to_byte(value.y())) << 8) |
           (std::uint32_t(to_byte(value.z())) << 16);
  return std::uint32_t(linear_to_srgb(value.x())) | (std::uint32_t(linear_to_srgb(value.y())) << 8) |
         (std::uint32_t(linear_to_srgb(value.z())) << 16);
}

float Texture::level_of_detail(float footprint) const {
  const float texels = footprint * transform_.stretch() * static_cast<float>(std::max(width(), height()));
  if (!(texels > 1.f)) return 0.f;
  return std::min(std::log2(texels), static_cast<float>(levels() - 1));
}

}  // namespace relight::render
