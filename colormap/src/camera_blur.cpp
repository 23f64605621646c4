#include "relight/colormap/camera_blur.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "relight/colormap/color_space.h"
#include "relight/core/gaussian_blur.h"

namespace relight::colormap {

namespace {

constexpr int kContrastReach = 3;  // pixels along the gradient to each side for the contrast

struct Luminance {
  Image<float> y;
  Image<std::uint8_t> clipped;  // a channel at the top of the range, or all at the bottom
};

Luminance linear_luminance(const ColorImage& image) {
  Luminance out{Image<float>(image.width(), image.height()), Image<std::uint8_t>(image.width(), image.height())};
  std::array<float, 256> linear{};  // a local copy of the decoding table: no call per pixel
  for (std::size_t v = 0; v < linear.size(); ++v) linear[v] = srgb8_to_linear(static_cast<std::uint8_t>(v));
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Rgb8 p = image.pixels()[i];
    out.y.pixels()[i] = 0.2126f * linear[p.r] + 0.7152f * linear[p.g] + 0.0722f * linear[p.b];
    out.clipped.pixels()[i] = std::max({p.r, p.g, p.b}) >= 254 || std::max({p.r, p.g, p.b}) <= 1;
  }
  return out;
}

/// Separable Gaussian of `weights` (radius `reach`) evaluated on `rows` x `cols` points around
/// (r, c): out[i][j] is at (r + i - rows / 2, c + j - cols / 2).
template <int Rows, int Cols>
std::array<std::array<float, Cols>, Rows> blurred_patch(const Image<float>& y, int r, int c,
                                                        const std::vector<float>& weights) {
  const int reach = static_cast<int>(weights.size() / 2);
  constexpr int kTall = Rows + 2 * 8;  // reach <= 8 (sigma <= 2.6)
  std::array<std::array<float, Cols>, kTall> horizontal{};
  const int top = r - Rows / 2 - reach, left = c - Cols / 2;
  for (int i = 0; i < Rows + 2 * reach; ++i) {
    // The patch's taps of this row (the callers keep the patch inside the image's margin).
    const float* taps = y.row(top + i).data() + (left - reach);
    for (int j = 0; j < Cols; ++j) {
      float sum = 0.f;
      for (std::size_t k = 0; k < weights.size(); ++k) sum += weights[k] * taps[static_cast<std::size_t>(j) + k];
      horizontal[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = sum;
    }
  }
  std::array<std::array<float, Cols>, Rows> out{};
  for (std::size_t i = 0; i < Rows; ++i)
    for (std::size_t j = 0; j < Cols; ++j) {
      float sum = 0.f;
      for (std::size_t k = 0; k < weights.size(); ++k) sum += weights[k] * horizontal[i + k][j];
      out[i][j] = sum;
    }
  return out;
}

}  // namespace

BlurEstimate estimate_camera_blur(const ColorImage& image, const BlurEstimationOptions& options,
                                  std::optional<Eigen::Vector2f> motion) {
  const double s0 = options.reblur_sigma, pre = std::max(0.0, options.pre_blur_sigma);
  // Noise adds to the gradient at the pixel and not to the re-blurred one, which would read as a
  // sharper edge: both gradients are taken on the image pre-blurred by `pre` (its variance is
  // taken out below), and G_s0 * G_pre = G_q with q^2 = s0^2 + pre^2.
  const double q = std::sqrt(s0 * s0 + pre * pre);
  if (!(s0 > 0.0) || q > 2.6) return {};
  const std::vector<float> pre_weights = gaussian_kernel(std::max(pre, 1e-3));
  const std::vector<float> reblur_weights = gaussian_kernel(q);
  const int reach = static_cast<int>(reblur_weights.size() / 2);
  const int margin = std::max(reach + 2, kContrastReach) + 2;
  const int width = image.width(), height = image.height();
  if (width <= 2 * margin || height <= 2 * margin) return {};
  const Luminance lum = linear_luminance(image);
  const Image<float>& y = lum.y;
  Eigen::Vector2f motion_direction = Eigen::Vector2f::Zero();
  if (motion && motion->norm() > 1e-6f) motion_direction = motion->normalized();

  // Candidates: the 2x2 blocks of a half-resolution luminance (its noise halved) with a step of
  // most of min_contrast across +-4 px along x or y (a diagonal edge keeps 1/sqrt 2 of it);
  // noise alone rarely makes one. Their pixels are tested below; an even share is measured.
  const int half_width = width / 2, half_height = height / 2;
  Image<float> half(half_width, half_height);
  for (int i = 0; i < half_height; ++i)
    for (int j = 0; j < half_width; ++j)
      half(i, j) = 0.25f * (y(2 * i, 2 * j) + y(2 * i, 2 * j + 1) + y(2 * i + 1, 2 * j) + y(2 * i + 1, 2 * j + 1));
  const float block_contrast = 0.7f * static_cast<float>(options.min_contrast);
  const int half_margin = margin / 2 + 1;
  std::vector<std::pair<int, int>> candidates;
  for (int i = half_margin; i < half_height - half_margin; ++i)
    for (int j = half_margin; j < half_width - half_margin; ++j) {
      const float cx = std::abs(half(i, j + 2) - half(i, j - 2)), cy = std::abs(half(i + 2, j) - half(i - 2, j));
      if (std::max(cx, cy) >= block_contrast) candidates.emplace_back(2 * i, 2 * j);
    }
  const float threshold = 0.25f * static_cast<float>(options.min_contrast) / kContrastReach;
  const std::size_t wanted = static_cast<std::size_t>(std::max(1, options.max_edges));
  const double step = std::max(1.0, double(candidates.size()) / double(wanted));

  std::vector<double> sigmas;
  for (double e = 0.0; e < double(candidates.size()); e += step) {
    const auto [block_row, block_col] = candidates[static_cast<std::size_t>(e)];
    // The pre-blurred image on the 6x6 pixels around the block (rows block_row - 2 ...): each
    // pixel's gradient and its neighbours' along it (a local maximum across the edge).
    const auto p = blurred_patch<6, 6>(y, block_row + 1, block_col + 1, pre_weights);
    for (int pixel = 0; pixel < 4; ++pixel) {
      const int a = pixel / 2, b = pixel % 2, r = block_row + a, c = block_col + b;
      if (lum.clipped(r, c)) continue;
      const auto gradient = [&](int i, int j) {
        const int patch_row = a + 2 + i, patch_col = b + 2 + j;  // in [1, 4]
        const auto row = static_cast<std::size_t>(patch_row), col = static_cast<std::size_t>(patch_col);
        return Eigen::Vector2f(0.5f * (p[row][col + 1] - p[row][col - 1]), 0.5f * (p[row + 1][col] - p[row - 1][col]));
      };
      const Eigen::Vector2f g = gradient(0, 0);
      const float m = g.norm();
      if (m < threshold) continue;
      const Eigen::Vector2f d = g / m;
      if (motion_direction != Eigen::Vector2f::Zero() &&
          std::abs(d.dot(motion_direction)) > static_cast<float>(options.max_motion_cosine))
        continue;
      const int dc = static_cast<int>(std::lround(d.x())), dr = static_cast<int>(std::lround(d.y()));
      if (gradient(dr, dc).norm() > m || gradient(-dr, -dc).norm() >= m) continue;
      // A step of enough contrast between the sides, nothing clipped on its profile.
      const int fc = static_cast<int>(std::lround(kContrastReach * d.x()));
      const int fr = static_cast<int>(std::lround(kContrastReach * d.y()));
      if (lum.clipped(r + fr, c + fc) || lum.clipped(r - fr, c - fc)) continue;
      if (y(r + fr, c + fc) - y(r - fr, c - fc) < static_cast<float>(options.min_contrast)) continue;
      // The re-blurred gradient from G_q at the four neighbours.
      const auto reblurred = blurred_patch<3, 3>(y, r, c, reblur_weights);
      const float bx = 0.5f * (reblurred[1][2] - reblurred[1][0]), by = 0.5f * (reblurred[2][1] - reblurred[0][1]);
      const double ratio = m / std::max(1e-12, std::hypot(double(bx), double(by)));
      if (ratio <= 1.0 + 1e-4) continue;
      const double variance = s0 * s0 / (ratio * ratio - 1.0) - 1.0 / 3.0 - pre * pre;
      const double sigma = std::sqrt(std::max(0.0, variance));
      if (sigma <= options.max_sigma) sigmas.push_back(sigma);
    }
  }
  if (sigmas.empty()) return {};
  const auto middle = sigmas.begin() + static_cast<std::ptrdiff_t>(sigmas.size() / 2);
  std::nth_element(sigmas.begin(), middle, sigmas.end());
  return {*middle, static_cast<int>(sigmas.size())};
}

}  // namespace relight::colormap
