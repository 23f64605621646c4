#pragma once
// The Gaussian point spread, separable, on any image of pixels that add and scale (float,
// Float3): the camera's blur in synth, the estimators' pre-blur and the virtual layer's defocus.
// Borders clamp to the edge pixel.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "relight/core/error.h"
#include "relight/core/image.h"

namespace relight {

/// Normalised weights of a Gaussian of `sigma` pixels over [-r, r], r = ceil(reach * sigma);
/// weights[i] is the weight of offset i - r.
[[nodiscard]] inline std::vector<float> gaussian_kernel(double sigma, double reach = 3.0) {
  const int radius = static_cast<int>(std::ceil(reach * sigma));
  std::vector<float> weights;
  weights.reserve(static_cast<std::size_t>(2 * radius + 1));
  float total = 0.f;
  for (int offset = -radius; offset <= radius; ++offset)
    total += weights.emplace_back(static_cast<float>(std::exp(-0.5 * offset * offset / (sigma * sigma))));
  for (float& w : weights) w /= total;
  return weights;
}

/// The Gaussian of `weights` (gaussian_kernel) over rows [row0, row1) x columns [col0, col1) of
/// `image` (borders clamped to the edge pixel), written row-major to `out`, which holds the
/// region: horizontally over the region's columns and the rows it reaches, then vertically.
template <class ImageType>
void gaussian_blur_region(const ImageType& image, int row0, int row1, int col0, int col1,
                          const std::vector<float>& weights, std::span<typename ImageType::value_type> out) {
  using Pixel = typename ImageType::value_type;
  const int radius = static_cast<int>(weights.size() / 2);
  const int width = image.width(), height = image.height();
  const auto columns = static_cast<std::size_t>(col1 - col0);
  const int tall = row1 - row0 + 2 * radius;
  if (out.size() < static_cast<std::size_t>(row1 - row0) * columns)
    throw LogicError("gaussian_blur_region: the output is smaller than the region");
  std::vector<Pixel> horizontal(static_cast<std::size_t>(tall) * columns);
  for (int i = 0; i < tall; ++i) {
    const Pixel* line = image.row(std::clamp(row0 - radius + i, 0, height - 1)).data();
    for (int j = 0; j < col1 - col0; ++j) {
      const int first = col0 + j - radius;
      Pixel sum{};
      if (first >= 0 && first + static_cast<int>(weights.size()) <= width) {  // inside: no clamping
        const Pixel* taps = line + first;
        for (std::size_t k = 0; k < weights.size(); ++k) sum = sum + weights[k] * taps[k];
      } else {
        for (std::size_t k = 0; k < weights.size(); ++k)
          sum = sum + weights[k] * line[std::clamp(first + static_cast<int>(k), 0, width - 1)];
      }
      horizontal[static_cast<std::size_t>(i) * columns + static_cast<std::size_t>(j)] = sum;
    }
  }
  const Pixel* rows = horizontal.data();
  Pixel* result = out.data();
  for (std::size_t i = 0; i < static_cast<std::size_t>(row1 - row0); ++i)
    for (std::size_t j = 0; j < columns; ++j) {
      Pixel sum{};
      for (std::size_t k = 0; k < weights.size(); ++k) sum = sum + weights[k] * rows[(i + k) * columns + j];
      result[i * columns + j] = sum;
    }
}

/// The image blurred by a Gaussian of `sigma` pixels (itself when sigma <= 0); any Image<Pixel>
/// or image type derived from one (RadianceImage, ...).
template <class ImageType>
[[nodiscard]] ImageType gaussian_blur(const ImageType& image, double sigma, double reach = 3.0) {
  if (!(sigma > 0.0)) return image;
  ImageType out(image.width(), image.height());
  gaussian_blur_region(image, 0, image.height(), 0, image.width(), gaussian_kernel(sigma, reach), out.pixels());
  return out;
}

}  // namespace relight
