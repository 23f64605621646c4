#include "relight/synth/camera_effects.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "random.h"
#include "relight/core/gaussian_blur.h"
#include "relight/core/parallel.h"

namespace relight::synth {

namespace {

constexpr std::uint64_t kColorNoiseStream = 0x636f6c6f72ULL;  // "color"

}  // namespace

RadianceImage blur_radiance(const RadianceImage& radiance, double sigma_px) {
  return gaussian_blur(radiance, sigma_px, 4.0);
}

ColorImage add_color_noise(const ColorImage& image, const ColorCameraEffects& effects, std::uint64_t seed,
                           std::uint64_t frame, int threads) {
  if (!(effects.noise_floor > 0.0) && !(effects.noise_gain > 0.0)) return image;
  ColorImage out(image.width(), image.height());
  parallel_for_each_row(image.height(), threads, [&](int row) {
    std::mt19937_64 rng(
        detail::stream_seed(seed, kColorNoiseStream ^ detail::mix(frame), static_cast<std::uint64_t>(row)));
    for (int col = 0; col < image.width(); ++col) {
      const Rgb8 p = image(row, col);
      std::uint8_t* channels[3] = {&out(row, col).r, &out(row, col).g, &out(row, col).b};
      const std::uint8_t codes[3] = {p.r, p.g, p.b};
      for (int ch = 0; ch < 3; ++ch) {
        const double noisy = codes[ch] + effects.noise_sigma(codes[ch]) * detail::gaussian(rng);
        *channels[ch] = static_cast<std::uint8_t>(std::clamp(std::lround(noisy), 0L, 255L));
      }
    }
  });
  return out;
}

}  // namespace relight::synth
