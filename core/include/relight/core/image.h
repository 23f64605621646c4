#pragma once
// Owning, contiguous, row-major image. Pixel (row, col) lives at data()[row * width() + col].
// One convention everywhere: operator()(row, col), i.e. (y, x), as OpenCV's Mat::at.
#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "relight/core/pixel.h"

namespace relight {

template <class T>
class Image {
 public:
  using value_type = T;

  Image() = default;
  Image(int width, int height, const T& fill = T{})
      : width_(width), height_(height),
        pixels_(static_cast<std::size_t>(checked(width)) * static_cast<std::size_t>(checked(height)), fill) {}

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] std::size_t size() const { return pixels_.size(); }
  [[nodiscard]] bool empty() const { return pixels_.empty(); }
  [[nodiscard]] bool in_bounds(int row, int col) const {
    return row >= 0 && col >= 0 && row < height_ && col < width_;
  }
  [[nodiscard]] bool same_shape(const auto& other) const {
    return width_ == other.width() && height_ == other.height();
  }

  T& operator()(int row, int col) {
    assert(in_bounds(row, col));
    return pixels_[index(row, col)];
  }
  const T& operator()(int row, int col) const {
    assert(in_bounds(row, col));
    return pixels_[index(row, col)];
  }

  [[nodiscard]] std::span<T> row(int r) { return {pixels_.data() + index(r, 0), static_cast<std::size_t>(width_)}; }
  [[nodiscard]] std::span<const T> row(int r) const {
    return {pixels_.data() + index(r, 0), static_cast<std::size_t>(width_)};
  }
  [[nodiscard]] std::span<T> pixels() { return pixels_; }
  [[nodiscard]] std::span<const T> pixels() const { return pixels_; }
  [[nodiscard]] T* data() { return pixels_.data(); }
  [[nodiscard]] const T* data() const { return pixels_.data(); }

  /// Raw bytes, for GPU transfers and hashing; only for trivially copyable pixels.
  [[nodiscard]] std::span<std::byte> bytes()
    requires std::is_trivially_copyable_v<T>
  {
    return std::as_writable_bytes(std::span<T>(pixels_));
  }
  [[nodiscard]] std::span<const std::byte> bytes() const
    requires std::is_trivially_copyable_v<T>
  {
    return std::as_bytes(std::span<const T>(pixels_));
  }

  void fill(const T& value) { std::fill(pixels_.begin(), pixels_.end(), value); }
  /// Reshape, keeping the allocation when the pixel count does not grow; contents are unspecified.
  void resize(int width, int height) {
    width_ = checked(width);
    height_ = checked(height);
    pixels_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  }

  friend bool operator==(const Image&, const Image&) = default;

 private:
  static int checked(int extent) {
    assert(extent >= 0);
    return extent < 0 ? 0 : extent;
  }
  [[nodiscard]] std::size_t index(int row, int col) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(col);
  }

  int width_ = 0;
  int height_ = 0;
  std::vector<T> pixels_;
};

// Domain image types. They are distinct types (not aliases) so that the frame graph can tell a
// NormalMap from a PositionMap when it checks that a reader and a writer agree on a buffer's type.
// Each converts to its Image<T> base, so generic image code takes them all.
#define RELIGHT_IMAGE_TYPE(Name, Pixel)              \
  struct Name : Image<Pixel> {                       \
    using Image<Pixel>::Image;                       \
    static constexpr const char* type_name = #Name;  \
  }

/// Depth in metres along the optical axis, 0 = no measurement (see is_valid_depth).
RELIGHT_IMAGE_TYPE(DepthMap, float);
/// 8-bit sRGB colour as the camera delivers it.
RELIGHT_IMAGE_TYPE(ColorImage, Rgb8);
/// Linear RGB radiance (HDR), unbounded.
RELIGHT_IMAGE_TYPE(RadianceImage, Float3);
/// Unit normals in the camera frame, (0,0,0) = no normal (see is_valid_normal).
RELIGHT_IMAGE_TYPE(NormalMap, Float3);
/// Camera-frame positions in metres, (0,0,0) = no position.
RELIGHT_IMAGE_TYPE(PositionMap, Float3);
/// Binary mask; 0 = off.
RELIGHT_IMAGE_TYPE(Mask, std::uint8_t);
/// Small integer labels (material ids, cluster ids); the producer documents what 0 means.
RELIGHT_IMAGE_TYPE(LabelImage, std::uint16_t);

#undef RELIGHT_IMAGE_TYPE

}  // namespace relight
