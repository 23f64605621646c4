#include "relight/colormap/camera_noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace relight::colormap {

namespace {

constexpr float kBandWidth = 256.f / kNoiseBands;
/// median |x| of a unit Gaussian, and the operator's response sigma per unit of noise sigma
constexpr float kMedianAbsGaussian = 0.6745f;
constexpr float kOperatorGain = 6.f;

float channel(const Rgb8& p, int c) { return static_cast<float>(c == 0 ? p.r : c == 1 ? p.g : p.b); }
float luma(const Rgb8& p) { return 0.299f * p.r + 0.587f * p.g + 0.114f * p.b; }

}  // namespace

bool NoiseProfile::valid() const {
  return std::any_of(samples.begin(), samples.end(), [](int n) { return n > 0; });
}

float NoiseProfile::at(float code, int channel_index) const {
  const float position = std::clamp(code / kBandWidth - 0.5f, 0.f, float(kNoiseBands - 1));
  const int low = std::min(static_cast<int>(position), kNoiseBands - 2);
  const float t = position - static_cast<float>(low);
  const auto c = static_cast<std::size_t>(channel_index);
  return (1.f - t) * sigma[static_cast<std::size_t>(low)][c] + t * sigma[static_cast<std::size_t>(low) + 1][c];
}

NoiseProfile estimate_camera_noise(const ColorImage& image, const NoiseEstimationOptions& options) {
  NoiseProfile profile;
  const int width = image.width(), height = image.height();
  if (width < 5 || height < 5) return profile;
  // Per band and channel, the operator's |response| at flat pixels.
  std::array<std::array<std::vector<float>, 3>, kNoiseBands> responses;
  const int stride = std::max(1, options.stride);
  const float flat = static_cast<float>(options.flat_gradient);
  for (int r = 2; r < height - 2; r += stride) {
    for (int c = 2; c < width - 2; c += stride) {
      // The 3x3 means of the luma around (r, c) give the local level and, by their Sobel
      // gradient, the flatness.
      std::array<std::array<float, 5>, 5> l{};
      std::array<const Rgb8*, 5> rows{};  // the 5x5 neighbourhood's rows, from column c - 2
      for (std::size_t i = 0; i < 5; ++i) rows[i] = image.row(r + static_cast<int>(i) - 2).data() + (c - 2);
      bool clipped = false;
      for (std::size_t i = 0; i < 5; ++i)
        for (std::size_t j = 0; j < 5; ++j) {
          const Rgb8 p = rows[i][j];
          l[i][j] = luma(p);
          const bool inner = i >= 1 && i <= 3 && j >= 1 && j <= 3;
          clipped = clipped || (inner && (std::max({p.r, p.g, p.b}) == 255 || std::min({p.r, p.g, p.b}) == 0));
        }
      if (clipped) continue;
      std::array<std::array<float, 3>, 3> m{};
      for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) {
          float sum = 0.f;
          for (std::size_t a = 0; a < 3; ++a)
            for (std::size_t b = 0; b < 3; ++b) sum += l[i + a][j + b];
          m[i][j] = sum / 9.f;
        }
      const float gx = (m[0][2] + 2 * m[1][2] + m[2][2]) - (m[0][0] + 2 * m[1][0] + m[2][0]);
      const float gy = (m[2][0] + 2 * m[2][1] + m[2][2]) - (m[0][0] + 2 * m[0][1] + m[0][2]);
      if (gx * gx + gy * gy > 64.f * flat * flat) continue;
      const int band = std::min(kNoiseBands - 1, static_cast<int>(m[1][1] / kBandWidth));
      for (int ch = 0; ch < 3; ++ch) {
        const auto v = [&](int i, int j) {
          return channel(rows[static_cast<std::size_t>(i) + 2][static_cast<std::size_t>(j) + 2], ch);
        };
        const float response = v(-1, -1) - 2 * v(-1, 0) + v(-1, 1) - 2 * v(0, -1) + 4 * v(0, 0) - 2 * v(0, 1) +
                               v(1, -1) - 2 * v(1, 0) + v(1, 1);
        responses[static_cast<std::size_t>(band)][static_cast<std::size_t>(ch)].push_back(std::abs(response));
      }
    }
  }
  std::vector<int> measured;
  for (int band = 0; band < kNoiseBands; ++band) {
    auto& per_channel = responses[static_cast<std::size_t>(band)];
    const int n = static_cast<int>(per_channel[0].size());
    if (n < options.min_samples) continue;
    profile.samples[static_cast<std::size_t>(band)] = n;
    measured.push_back(band);
    for (int ch = 0; ch < 3; ++ch) {
      auto& values = per_channel[static_cast<std::size_t>(ch)];
      const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
      std::nth_element(values.begin(), middle, values.end());
      profile.sigma[static_cast<std::size_t>(band)][static_cast<std::size_t>(ch)] =
          *middle / (kOperatorGain * kMedianAbsGaussian);
    }
  }
  if (measured.empty()) return profile;
  // Unmeasured bands: linear between the nearest measured ones, constant beyond them.
  for (int band = 0; band < kNoiseBands; ++band) {
    if (profile.samples[static_cast<std::size_t>(band)] > 0) continue;
    const auto above = std::lower_bound(measured.begin(), measured.end(), band);
    const int hi = above == measured.end() ? measured.back() : *above;
    const int lo = above == measured.begin() ? measured.front() : *(above - 1);
    const float t = hi == lo ? 0.f : float(band - lo) / float(hi - lo);
    for (std::size_t ch = 0; ch < 3; ++ch)
      profile.sigma[static_cast<std::size_t>(band)][ch] = (1.f - t) * profile.sigma[static_cast<std::size_t>(lo)][ch] +
                                                          t * profile.sigma[static_cast<std::size_t>(hi)][ch];
  }
  return profile;
}

}  // namespace relight::colormap
