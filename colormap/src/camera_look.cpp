#include "relight/colormap/camera_look.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

#include "relight/colormap/color_space.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::colormap {

namespace {

/// Linear display values below this change no 8-bit sRGB code (the steepest part of the curve,
/// near black, needs ~0.0003 per code).
constexpr float kNegligible = 1e-4f;

struct Box {
  int row0 = 0, row1 = 0, col0 = 0, col1 = 0;  // half-open
  [[nodiscard]] bool empty() const { return row0 >= row1 || col0 >= col1; }
};

bool touched(const VirtualLayer& layer, std::size_t i) {
  const Float3& d = layer.delta.pixels()[i];
  return layer.coverage.pixels()[i] > 0.f || std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) > kNegligible;
}

/// The pixels the layer touches, grown by `reach` and clipped to the image.
Box touched_box(const VirtualLayer& layer, int reach) {
  const int width = layer.coverage.width(), height = layer.coverage.height();
  Box box{height, 0, width, 0};
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      if (!touched(layer, static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c)))
        continue;
      box.row0 = std::min(box.row0, r);
      box.row1 = std::max(box.row1, r + 1);
      box.col0 = std::min(box.col0, c);
      box.col1 = std::max(box.col1, c + 1);
    }
  }
  if (box.empty()) return box;
  return {std::max(0, box.row0 - reach), std::min(height, box.row1 + reach), std::max(0, box.col0 - reach),
          std::min(width, box.col1 + reach)};
}

std::vector<float> gaussian_weights(float sigma) {
  const int radius = static_cast<int>(std::ceil(3.f * sigma));
  std::vector<float> weights(static_cast<std::size_t>(2 * radius + 1));
  float sum = 0.f;
  for (int i = -radius; i <= radius; ++i) {
    const float w = std::exp(-0.5f * float(i * i) / (sigma * sigma));
    weights[static_cast<std::size_t>(i + radius)] = w;
    sum += w;
  }
  for (float& w : weights) w /= sum;
  return weights;
}

/// Separable Gaussian over `box` (reads beyond the box within the image, clamped at its edges).
template <class T>
void gaussian(Image<T>& image, const Box& box, const std::vector<float>& weights, int threads) {
  const int radius = static_cast<int>(weights.size() / 2);
  const int width = image.width(), height = image.height();
  const int rows0 = std::max(0, box.row0 - radius), rows1 = std::min(height, box.row1 + radius);
  Image<T> horizontal(box.col1 - box.col0, rows1 - rows0);
  parallel_for_each_row(rows1 - rows0, threads, [&](int r) {
    for (int c = box.col0; c < box.col1; ++c) {
      T sum{};
      for (int k = -radius; k <= radius; ++k)
        sum = sum + weights[static_cast<std::size_t>(k + radius)] * image(rows0 + r, std::clamp(c + k, 0, width - 1));
      horizontal(r, c - box.col0) = sum;
    }
  });
  parallel_for_each_row(box.row1 - box.row0, threads, [&](int r) {
    const int row = box.row0 + r;
    for (int c = box.col0; c < box.col1; ++c) {
      T sum{};
      for (int k = -radius; k <= radius; ++k)
        sum = sum + weights[static_cast<std::size_t>(k + radius)] *
                        horizontal(std::clamp(row + k, rows0, rows1 - 1) - rows0, c - box.col0);
      image(row, c) = sum;
    }
  });
}

template <class T>
T bilinear(const Image<T>& image, float row, float col) {
  const float r = std::clamp(row, 0.f, float(image.height() - 1)), c = std::clamp(col, 0.f, float(image.width() - 1));
  const int r0 = std::min(static_cast<int>(r), image.height() - 2 < 0 ? 0 : image.height() - 2);
  const int c0 = std::min(static_cast<int>(c), image.width() - 2 < 0 ? 0 : image.width() - 2);
  const int r1 = std::min(r0 + 1, image.height() - 1), c1 = std::min(c0 + 1, image.width() - 1);
  const float fr = r - float(r0), fc = c - float(c0);
  return (1.f - fr) * ((1.f - fc) * image(r0, c0) + fc * image(r0, c1)) +
         fr * ((1.f - fc) * image(r1, c0) + fc * image(r1, c1));
}

/// Box filter along each pixel's motion, centred on the pixel (the render is of the frame's pose,
/// the middle of the exposure as far as the pose says).
template <class T>
void motion_blur(Image<T>& image, const Box& box, const MotionField& motion, int threads) {
  const Image<T> source = image;
  parallel_for_each_row(box.row1 - box.row0, threads, [&](int r) {
    const int row = box.row0 + r;
    for (int c = box.col0; c < box.col1; ++c) {
      const Float3 m = motion.at(float(row), float(c));
      const int samples = std::max(1, static_cast<int>(std::ceil(std::hypot(m.x, m.y))) + 1);
      if (samples == 1) continue;
      T sum{};
      for (int k = 0; k < samples; ++k) {
        const float t = (float(k) + 0.5f) / float(samples) - 0.5f;
        sum = sum + bilinear(source, float(row) + t * m.y, float(c) + t * m.x);
      }
      image(row, c) = (1.f / float(samples)) * sum;
    }
  });
}

std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Three unit Gaussians for one pixel of one frame (Box-Muller on hashed uniforms: the same for
/// any thread count).
std::array<float, 3> gaussians(std::uint64_t seed, std::size_t pixel) {
  const auto uniform = [](std::uint64_t bits) { return (static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53; };
  const std::uint64_t a = mix(seed ^ mix(2 * pixel)), b = mix(seed ^ mix(2 * pixel + 1));
  const double radius1 = std::sqrt(-2.0 * std::log(uniform(a))), angle1 = 2.0 * std::numbers::pi * uniform(mix(a));
  const double radius2 = std::sqrt(-2.0 * std::log(uniform(b))), angle2 = 2.0 * std::numbers::pi * uniform(mix(b));
  return {float(radius1 * std::cos(angle1)), float(radius1 * std::sin(angle1)), float(radius2 * std::cos(angle2))};
}

}  // namespace

CameraArtefacts parse_camera_artefacts(const std::string& text) {
  if (text == "all") return {};
  if (text == "none") return {false, false, false};
  CameraArtefacts out{false, false, false};
  std::stringstream list(text);
  std::string item;
  bool any = false;
  while (std::getline(list, item, ',')) {
    if (item == "blur")
      out.blur = true;
    else if (item == "motion")
      out.motion = true;
    else if (item == "noise")
      out.noise = true;
    else
      throw Error("camera artefacts: unknown '" + item + "' in '" + text +
                  "' (choices: all, none, or a comma-separated list of blur, motion, noise)");
    any = true;
  }
  if (!any) throw Error("camera artefacts: empty list (choices: all, none, or blur,motion,noise)");
  return out;
}

std::string to_string(const CameraArtefacts& artefacts) {
  if (artefacts == CameraArtefacts{}) return "all";
  if (!artefacts.any()) return "none";
  std::string out;
  for (const auto& [on, name] :
       {std::pair{artefacts.blur, "blur"}, {artefacts.motion, "motion"}, {artefacts.noise, "noise"}})
    if (on) out += (out.empty() ? "" : ",") + std::string(name);
  return out;
}

Float3 MotionField::at(float row, float col) const {
  if (motion.empty()) return {};
  // Cell i spans pixels [i cell, (i + 1) cell): its centre is at (i + 0.5) cell - 0.5.
  return bilinear(motion, (row + 0.5f) / float(cell) - 0.5f, (col + 0.5f) / float(cell) - 0.5f);
}

float MotionField::max_length() const {
  float longest = 0.f;
  for (const Float3& m : motion.pixels()) longest = std::max(longest, std::hypot(m.x, m.y));
  return longest;
}

void blur_layer(VirtualLayer& layer, float sigma_px, const MotionField* motion, int threads) {
  const bool defocus = sigma_px > 0.05f;
  const bool moving = motion && !motion->empty() && motion->max_length() > 0.5f;
  if (!defocus && !moving) return;
  const int reach = (defocus ? static_cast<int>(std::ceil(3.f * sigma_px)) : 0) +
                    (moving ? static_cast<int>(std::ceil(0.5f * motion->max_length())) : 0) + 1;
  const Box box = touched_box(layer, reach);
  if (box.empty()) return;
  if (defocus) {
    const std::vector<float> weights = gaussian_weights(sigma_px);
    gaussian(layer.virtual_color, box, weights, threads);
    gaussian(layer.coverage, box, weights, threads);
    gaussian(layer.delta, box, weights, threads);
  }
  if (moving) {
    motion_blur(layer.virtual_color, box, *motion, threads);
    motion_blur(layer.coverage, box, *motion, threads);
    motion_blur(layer.delta, box, *motion, threads);
  }
}

ColorImage composite_layer(const ColorImage& camera, VirtualLayer layer, const CameraLook* look, int threads) {
  if (!camera.same_shape(layer.virtual_color) || !camera.same_shape(layer.coverage) || !camera.same_shape(layer.delta))
    throw Error("differential composite: the camera image and the rendered images differ in size");
  const bool noise = look && look->artefacts.noise && look->noise.valid();
  if (look) {
    const float sigma = look->artefacts.blur ? look->blur_sigma_px : 0.f;
    const MotionField* motion = look->artefacts.motion ? &look->motion : nullptr;
    blur_layer(layer, sigma, motion, threads);
  }
  const int width = camera.width();
  ColorImage out(camera.width(), camera.height());
  parallel_for_each_row(camera.height(), threads, [&](int row) {
    for (int col = 0; col < width; ++col) {
      const std::size_t i =
          static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col);
      const float c = layer.coverage.pixels()[i];
      const Float3& d = layer.delta.pixels()[i];
      if (c == 0.f && d == Float3{}) {
        out.pixels()[i] = camera.pixels()[i];
        continue;
      }
      const Float3 linear = layer.virtual_color.pixels()[i] + (1.f - c) * decode_srgb8(camera.pixels()[i]) + d;
      if (!noise || c <= 0.f) {
        out.pixels()[i] = encode_srgb8(linear);
        continue;
      }
      const float codes[3] = {255.f * linear_to_srgb(std::clamp(linear.x, 0.f, 1.f)),
                              255.f * linear_to_srgb(std::clamp(linear.y, 0.f, 1.f)),
                              255.f * linear_to_srgb(std::clamp(linear.z, 0.f, 1.f))};
      const float luma = 0.299f * codes[0] + 0.587f * codes[1] + 0.114f * codes[2];
      const float share = std::sqrt(std::max(0.f, 1.f - (1.f - c) * (1.f - c)));
      const std::array<float, 3> g = gaussians(look->seed, i);
      std::uint8_t encoded[3];
      for (int ch = 0; ch < 3; ++ch) {
        const float v = codes[ch] + share * look->noise.at(luma, ch) * g[static_cast<std::size_t>(ch)];
        encoded[ch] = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.f, 255.f)));
      }
      out.pixels()[i] = {encoded[0], encoded[1], encoded[2]};
    }
  });
  return out;
}

}  // namespace relight::colormap
