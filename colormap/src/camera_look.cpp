#include "relight/colormap/camera_look.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <sstream>
#include <vector>

#include "relight/colormap/color_space.h"
#include "relight/core/error.h"
#include "relight/core/gaussian_blur.h"
#include "relight/core/parallel.h"

namespace relight::colormap {

namespace {

constexpr int kTile = 16;  // pixels per side of the blur's work tiles
/// Linear display values: a tile whose differential varies by less than this (and which the
/// virtual object does not cover) is smooth, and blurring it would change no 8-bit code by more
/// than a fraction: it is left as it is (the indirect light a virtual object adds everywhere).
constexpr float kSmoothRange = 2e-3f;

/// What a tile of the layer needs from the blur. Covered: the virtual object is within reach, so
/// its colour and coverage are filtered too; Delta: only the differential (a shadow's edge).
enum TileActivity : std::uint8_t { kInactive = 0, kDeltaOnly = 1, kCovered = 2 };

/// The activity of every tile (row-major): covered by the virtual object, or with a differential
/// that changes within it, grown by `reach` pixels. One pass over the layer, rows of tiles in
/// parallel, each tile stopping as soon as it is known to be covered.
std::vector<std::uint8_t> active_tiles(const VirtualLayer& layer, int reach, int columns, int rows, int threads) {
  const int width = layer.coverage.width(), height = layer.coverage.height();
  const auto tile_index = [columns](int ty, int tx) {
    return static_cast<std::size_t>(ty) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(tx);
  };
  std::vector<std::uint8_t> own(static_cast<std::size_t>(columns) * static_cast<std::size_t>(rows), kInactive);
  parallel_for_each_row(
      rows, threads,
      [&](int ty) {
        const int r1 = std::min(height, (ty + 1) * kTile);
        for (int tx = 0; tx < columns; ++tx) {
          const int c0 = tx * kTile, c1 = std::min(width, (tx + 1) * kTile);
          bool covered = false;
          Float3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
          for (int r = ty * kTile; r < r1 && !covered; ++r) {
            const auto coverage =
                layer.coverage.row(r).subspan(static_cast<std::size_t>(c0), static_cast<std::size_t>(c1 - c0));
            const auto delta =
                layer.delta.row(r).subspan(static_cast<std::size_t>(c0), static_cast<std::size_t>(c1 - c0));
            for (std::size_t k = 0; k < coverage.size(); ++k) {
              covered = covered || coverage[k] > 0.f;
              lo = {std::min(lo.x, delta[k].x), std::min(lo.y, delta[k].y), std::min(lo.z, delta[k].z)};
              hi = {std::max(hi.x, delta[k].x), std::max(hi.y, delta[k].y), std::max(hi.z, delta[k].z)};
            }
          }
          const Float3 range = hi - lo;
          own[tile_index(ty, tx)] = covered                                                ? kCovered
                                    : std::max({range.x, range.y, range.z}) > kSmoothRange ? kDeltaOnly
                                                                                           : kInactive;
        }
      },
      1);
  const int grow = (reach + kTile - 1) / kTile;
  std::vector<std::uint8_t> grown(own.size(), kInactive);
  for (int ty = 0; ty < rows; ++ty)
    for (int tx = 0; tx < columns; ++tx) {
      std::uint8_t most = kInactive;
      for (int y = std::max(0, ty - grow); y <= std::min(rows - 1, ty + grow); ++y)
        for (int x = std::max(0, tx - grow); x <= std::min(columns - 1, tx + grow); ++x)
          most = std::max(most, own[tile_index(y, x)]);
      grown[tile_index(ty, tx)] = most;
    }
  return grown;
}

/// One tile's share of a filter: `filter(row, col)` of every pixel of the tile, computed from
/// the unchanged image and written back once every tile is done.
struct TileBox {
  int row0, row1, col0, col1;
  bool covered;  ///< the virtual object is within reach: its colour and coverage are filtered too
};

/// The separable Gaussian of `weights` over the tile (borders clamp to the image's edge).
template <class T>
std::vector<T> gaussian_tile(const Image<T>& image, const TileBox& box, const std::vector<float>& weights) {
  std::vector<T> out(static_cast<std::size_t>(box.row1 - box.row0) * static_cast<std::size_t>(box.col1 - box.col0));
  gaussian_blur_region(image, box.row0, box.row1, box.col0, box.col1, weights, std::span<T>(out));
  return out;
}

/// One tile's filtered parts of the layer, row-major over the tile.
struct TileResult {
  std::vector<Float3> colour;
  std::vector<float> coverage;
  std::vector<Float3> delta;
};

/// A bilinear sample of the layer: the four pixel indices and the weights along row and column.
struct Tap {
  std::size_t i00, i01, i10, i11;
  float fr, fc;
};

Tap tap_at(int width, int height, float row, float col) {
  const float r = std::clamp(row, 0.f, float(height - 1)), c = std::clamp(col, 0.f, float(width - 1));
  const int r0 = std::min(static_cast<int>(r), std::max(0, height - 2)),
            c0 = std::min(static_cast<int>(c), std::max(0, width - 2));
  const int r1 = std::min(r0 + 1, height - 1), c1 = std::min(c0 + 1, width - 1);
  const auto index = [width](int y, int x) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
  };
  return {index(r0, c0), index(r0, c1), index(r1, c0), index(r1, c1), r - float(r0), c - float(c0)};
}

template <class T>
T sample(std::span<const T> pixels, const Tap& t) {
  return (1.f - t.fr) * ((1.f - t.fc) * pixels[t.i00] + t.fc * pixels[t.i01]) +
         t.fr * ((1.f - t.fc) * pixels[t.i10] + t.fc * pixels[t.i11]);
}

template <class T>
T bilinear(const Image<T>& image, float row, float col) {
  return sample(image.pixels(), tap_at(image.width(), image.height(), row, col));
}

/// A box filter along each pixel's motion, centred on the pixel (the render is of the frame's
/// pose, the middle of the exposure as far as the pose says): the taps are found once per pixel
/// and applied to the three parts of the layer.
TileResult motion_tile(const VirtualLayer& layer, const TileBox& box, const MotionField& motion) {
  const int width = layer.coverage.width(), height = layer.coverage.height();
  TileResult out;
  const auto size = static_cast<std::size_t>(box.row1 - box.row0) * static_cast<std::size_t>(box.col1 - box.col0);
  if (box.covered) {
    out.colour.reserve(size);
    out.coverage.reserve(size);
  }
  out.delta.reserve(size);
  std::vector<Tap> taps;
  for (int row = box.row0; row < box.row1; ++row)
    for (int col = box.col0; col < box.col1; ++col) {
      Float3 m = motion.at(float(row), float(col));
      const float full = std::sqrt(m.x * m.x + m.y * m.y), length = std::min(full, kMaxMotionPx);
      const int samples = std::isfinite(full) ? std::max(1, static_cast<int>(std::ceil(length)) + 1) : 1;
      if (samples == 1) {
        if (box.covered) {
          out.colour.push_back(layer.virtual_color(row, col));
          out.coverage.push_back(layer.coverage(row, col));
        }
        out.delta.push_back(layer.delta(row, col));
        continue;
      }
      if (full > length) m = (length / full) * m;
      taps.clear();
      for (int k = 0; k < samples; ++k) {
        const float t = (float(k) + 0.5f) / float(samples) - 0.5f;
        taps.push_back(tap_at(width, height, float(row) + t * m.y, float(col) + t * m.x));
      }
      const float weight = 1.f / float(samples);
      Float3 colour, delta;
      float coverage = 0.f;
      for (const Tap& t : taps) delta += sample(layer.delta.pixels(), t);
      out.delta.push_back(weight * delta);
      if (!box.covered) continue;
      for (const Tap& t : taps) {
        colour += sample(layer.virtual_color.pixels(), t);
        coverage += sample(layer.coverage.pixels(), t);
      }
      out.colour.push_back(weight * colour);
      out.coverage.push_back(weight * coverage);
    }
  return out;
}

/// Applies `filter(layer, box)` (a TileResult) over the active tiles: every tile reads the
/// unchanged layer, then all are written back.
template <class Filter>
void filter_active_tiles(VirtualLayer& layer, const std::vector<std::uint8_t>& active, int columns, int threads,
                         const Filter& filter) {
  const int width = layer.coverage.width(), height = layer.coverage.height();
  std::vector<TileBox> boxes;
  for (std::size_t t = 0; t < active.size(); ++t) {
    if (!active[t]) continue;
    const int ty = static_cast<int>(t) / columns, tx = static_cast<int>(t) % columns;
    boxes.push_back({ty * kTile, std::min(height, (ty + 1) * kTile), tx * kTile, std::min(width, (tx + 1) * kTile),
                     active[t] == kCovered});
  }
  std::vector<TileResult> results(boxes.size());
  parallel_for_each_row(
      static_cast<int>(boxes.size()), threads,
      [&](int b) { results[static_cast<std::size_t>(b)] = filter(layer, boxes[static_cast<std::size_t>(b)]); }, 1);
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const TileBox& box = boxes[b];
    std::size_t i = 0;
    for (int row = box.row0; row < box.row1; ++row)
      for (int col = box.col0; col < box.col1; ++col, ++i) {
        if (box.covered) {
          layer.virtual_color(row, col) = results[b].colour[i];
          layer.coverage(row, col) = results[b].coverage[i];
        }
        layer.delta(row, col) = results[b].delta[i];
      }
  }
}

std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

constexpr std::size_t kQuantiles = 4096;

/// Phi^-1((k + 0.5) / kQuantiles): a unit Gaussian from 12 random bits (bisection on erfc, once).
const std::array<float, kQuantiles>& gaussian_quantiles() {
  static const std::array<float, kQuantiles> table = [] {
    std::array<float, kQuantiles> out{};
    for (std::size_t k = 0; k < kQuantiles; ++k) {
      const double p = (static_cast<double>(k) + 0.5) / static_cast<double>(kQuantiles);
      double lo = -8.0, hi = 8.0;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(-mid / std::numbers::sqrt2) < p ? lo : hi) = mid;
      }
      out[k] = static_cast<float>(0.5 * (lo + hi));
    }
    return out;
  }();
  return table;
}

/// Three unit Gaussians for one pixel of one frame (hashed, so the same for any thread count).
std::array<float, 3> gaussians(std::uint64_t seed, std::size_t pixel) {
  const std::array<float, kQuantiles>& q = gaussian_quantiles();
  const std::uint64_t bits = mix(seed ^ mix(pixel));
  return {q[bits & (kQuantiles - 1)], q[(bits >> 16) & (kQuantiles - 1)], q[(bits >> 32) & (kQuantiles - 1)]};
}

/// 255 linear_to_srgb(c) for c in [0, 1], linear between 4096 table points (the noise's
/// intensity and code: a hundredth of a code off at most).
float srgb_code(float linear) {
  static const std::array<float, 4097> table = [] {
    std::array<float, 4097> out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = 255.f * linear_to_srgb(float(i) / 4096.f);
    return out;
  }();
  const float x = (linear > 0.f ? std::min(linear, 1.f) : 0.f) * 4096.f;  // NaN: 0
  const auto i = std::min<std::size_t>(static_cast<std::size_t>(x), 4095);
  const float t = x - static_cast<float>(i);
  return table[i] + t * (table[i + 1] - table[i]);
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
      throw Error(std::string("camera artefacts: unknown '")
                      .append(item)
                      .append("' in '")
                      .append(text)
                      .append("' (choices: all, none, or a comma-separated list of blur, motion, noise)"));
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
    if (on) {
      if (!out.empty()) out += ',';
      out += name;
    }
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
  const float longest = motion && !motion->empty() ? std::min(motion->max_length(), kMaxMotionPx) : 0.f;
  const bool moving = longest > 0.5f;
  if (!defocus && !moving) return;
  const int reach = (defocus ? static_cast<int>(std::ceil(3.f * sigma_px)) : 0) +
                    (moving ? static_cast<int>(std::ceil(0.5f * longest)) : 0) + 1;
  const int columns = (layer.coverage.width() + kTile - 1) / kTile,
            rows = (layer.coverage.height() + kTile - 1) / kTile;
  const std::vector<std::uint8_t> active = active_tiles(layer, reach, columns, rows, threads);
  if (defocus) {
    const std::vector<float> weights = gaussian_kernel(sigma_px);
    filter_active_tiles(layer, active, columns, threads, [&](const VirtualLayer& source, const TileBox& box) {
      if (!box.covered) return TileResult{{}, {}, gaussian_tile(source.delta, box, weights)};
      return TileResult{gaussian_tile(source.virtual_color, box, weights), gaussian_tile(source.coverage, box, weights),
                        gaussian_tile(source.delta, box, weights)};
    });
  }
  if (moving) {
    filter_active_tiles(layer, active, columns, threads, [&](const VirtualLayer& source, const TileBox& box) {
      return motion_tile(source, box, *motion);
    });
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
      const float codes[3] = {srgb_code(linear.x), srgb_code(linear.y), srgb_code(linear.z)};
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
