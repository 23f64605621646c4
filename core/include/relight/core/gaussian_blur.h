#pragma once
// The Gaussian point spread, separable, on any image of pixels that add and scale (float,
// Float3): the camera's blur in synth, the estimators' pre-blur and the virtual layer's defocus.
// Borders clamp to the edge pixel.
#include <cmath>
#include <cstddef>
#include <vector>

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

/// The image blurred by a Gaussian of `sigma` pixels (itself when sigma <= 0); any Image<Pixel>
/// or image type derived from one (RadianceImage, ...).
template <class ImageType>
[[nodiscard]] ImageType gaussian_blur(const ImageType& image, double sigma, double reach = 3.0) {
  using Pixel = typename ImageType::value_type;
  if (!(sigma > 0.0)) return image;
  const std::vector<float> weights = gaussian_kernel(sigma, reach);
  const int radius = static_cast<int>(weights.size() / 2);
  const int width = image.width(), height = image.height();
  ImageType horizontal(width, height), out(width, height);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      Pixel sum{};
      for (std::size_t k = 0; k < weights.size(); ++k)
        sum = sum + weights[k] * image(r, std::clamp(c + static_cast<int>(k) - radius, 0, width - 1));
      horizontal(r, c) = sum;
    }
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      Pixel sum{};
      for (std::size_t k = 0; k < weights.size(); ++k)
        sum = sum + weights[k] * horizontal(std::clamp(r + static_cast<int>(k) - radius, 0, height - 1), c);
      out(r, c) = sum;
    }
  return out;
}

}  // namespace relight
