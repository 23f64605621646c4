#include "relight/colormap/camera_blur.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "relight/colormap/color_space.h"

namespace relight::colormap {

namespace {

constexpr int kContrastReach = 3;  // pixels along the gradient to each side for the contrast

struct Luminance {
  Image<float> y;
  Image<std::uint8_t> clipped;  // a channel at the top of the range, or all at the bottom
};

Luminance linear_luminance(const ColorImage& image) {
  Luminance out{Image<float>(image.width(), image.height()), Image<std::uint8_t>(image.width(), image.height())};
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Rgb8 p = image.pixels()[i];
    const Float3 c = decode_srgb8(p);
    out.y.pixels()[i] = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
    out.clipped.pixels()[i] = std::max({p.r, p.g, p.b}) >= 254 || std::max({p.r, p.g, p.b}) <= 1;
  }
  return out;
}

Image<float> gaussian_blurred(const Image<float>& image, double sigma) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<float> weights(static_cast<std::size_t>(2 * radius + 1));
  float total = 0.f;
  for (int i = -radius; i <= radius; ++i)
    total += weights[static_cast<std::size_t>(i + radius)] =
        static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
  for (float& w : weights) w /= total;
  const int width = image.width(), height = image.height();
  Image<float> horizontal(width, height), out(width, height);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      float sum = 0.f;
      for (int k = -radius; k <= radius; ++k)
        sum += weights[static_cast<std::size_t>(k + radius)] * image(r, std::clamp(c + k, 0, width - 1));
      horizontal(r, c) = sum;
    }
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      float sum = 0.f;
      for (int k = -radius; k <= radius; ++k)
        sum += weights[static_cast<std::size_t>(k + radius)] * horizontal(std::clamp(r + k, 0, height - 1), c);
      out(r, c) = sum;
    }
  return out;
}

struct Edge {
  int row, col;
  float gradient;  // |grad Y| by central differences
};

}  // namespace

BlurEstimate estimate_camera_blur(const ColorImage& image, const BlurEstimationOptions& options,
                                  std::optional<Eigen::Vector2f> motion) {
  const double s0 = options.reblur_sigma;
  const int reach = static_cast<int>(std::ceil(3.0 * s0));
  const int margin = std::max(reach + 1, kContrastReach + 1) + 1;
  const int width = image.width(), height = image.height();
  if (width <= 2 * margin || height <= 2 * margin || !(s0 > 0.0)) return {};
  Luminance lum = linear_luminance(image);
  // Noise adds to the gradient at the pixel and not to the re-blurred one, which would read as a
  // sharper edge: both are measured on the image pre-blurred by a known Gaussian (its variance
  // is taken out below), which averages the noise away.
  const double pre = options.pre_blur_sigma;
  if (pre > 0.0) lum.y = gaussian_blurred(lum.y, pre);
  const Image<float>& y = lum.y;
  Eigen::Vector2f motion_direction = Eigen::Vector2f::Zero();
  if (motion && motion->norm() > 1e-6f) motion_direction = motion->normalized();

  const auto gradient = [&](int r, int c) {
    return Eigen::Vector2f(0.5f * (y(r, c + 1) - y(r, c - 1)), 0.5f * (y(r + 1, c) - y(r - 1, c)));
  };
  // Edge pixels: the gradient a local maximum along its direction, a step of enough contrast
  // between the sides, nothing clipped on the profile.
  std::vector<Edge> edges;
  for (int r = margin; r < height - margin; ++r) {
    for (int c = margin; c < width - margin; ++c) {
      const Eigen::Vector2f g = gradient(r, c);
      const float m = g.norm();
      if (m < 0.25f * static_cast<float>(options.min_contrast) / kContrastReach) continue;
      const Eigen::Vector2f d = g / m;
      if (motion_direction != Eigen::Vector2f::Zero() &&
          std::abs(d.dot(motion_direction)) > static_cast<float>(options.max_motion_cosine))
        continue;
      const int dc = static_cast<int>(std::lround(d.x())), dr = static_cast<int>(std::lround(d.y()));
      if (gradient(r + dr, c + dc).norm() > m || gradient(r - dr, c - dc).norm() >= m) continue;
      const int fc = static_cast<int>(std::lround(kContrastReach * d.x()));
      const int fr = static_cast<int>(std::lround(kContrastReach * d.y()));
      if (lum.clipped(r, c) || lum.clipped(r + fr, c + fc) || lum.clipped(r - fr, c - fc)) continue;
      if (y(r + fr, c + fc) - y(r - fr, c - fc) < static_cast<float>(options.min_contrast)) continue;
      edges.push_back({r, c, m});
    }
  }
  if (edges.empty()) return {};

  std::vector<float> weights(static_cast<std::size_t>(2 * reach + 1));
  float weight_sum = 0.f;
  for (int i = -reach; i <= reach; ++i) {
    weights[static_cast<std::size_t>(i + reach)] = static_cast<float>(std::exp(-0.5 * i * i / (s0 * s0)));
    weight_sum += weights[static_cast<std::size_t>(i + reach)];
  }
  for (float& w : weights) w /= weight_sum;
  const auto reblurred = [&](int r, int c) {
    float sum = 0.f;
    for (int i = -reach; i <= reach; ++i) {
      float row_sum = 0.f;
      for (int j = -reach; j <= reach; ++j) row_sum += weights[static_cast<std::size_t>(j + reach)] * y(r + i, c + j);
      sum += weights[static_cast<std::size_t>(i + reach)] * row_sum;
    }
    return sum;
  };

  const std::size_t step =
      std::max<std::size_t>(1, edges.size() / static_cast<std::size_t>(std::max(1, options.max_edges)));
  std::vector<double> sigmas;
  for (std::size_t e = 0; e < edges.size(); e += step) {
    const auto [r, c, m] = edges[e];
    const float gx = 0.5f * (reblurred(r, c + 1) - reblurred(r, c - 1));
    const float gy = 0.5f * (reblurred(r + 1, c) - reblurred(r - 1, c));
    const double ratio = m / std::max(1e-12, std::hypot(double(gx), double(gy)));
    if (ratio <= 1.0 + 1e-4) continue;
    const double variance = s0 * s0 / (ratio * ratio - 1.0) - 1.0 / 3.0 - pre * pre;
    const double sigma = std::sqrt(std::max(0.0, variance));
    if (sigma <= options.max_sigma) sigmas.push_back(sigma);
  }
  if (sigmas.empty()) return {};
  const auto middle = sigmas.begin() + static_cast<std::ptrdiff_t>(sigmas.size() / 2);
  std::nth_element(sigmas.begin(), middle, sigmas.end());
  return {*middle, static_cast<int>(sigmas.size())};
}

}  // namespace relight::colormap
