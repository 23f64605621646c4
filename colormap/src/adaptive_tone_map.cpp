// Reinhard's adapted key (adaptive_tone_map.h).
#include "relight/colormap/adaptive_tone_map.h"

#include <algorithm>
#include <cmath>

#include "relight/core/error.h"

namespace relight::colormap {

namespace {

/// Reinhard's delta of eq. 1: keeps log() finite; far below any lit pixel's luminance.
constexpr double kLogDelta = 1e-6;

}  // namespace

SceneLuminance scene_luminance(const RadianceImage& radiance, int stride) {
  if (stride < 1) throw LogicError("scene_luminance: stride must be positive");
  SceneLuminance scene;
  double log_sum = 0.0;
  for (int y = 0; y < radiance.height(); y += stride) {
    const auto row = radiance.row(y);
    for (std::size_t x = 0; x < row.size(); x += static_cast<std::size_t>(stride)) {
      const Float3& c = row[x];
      const double l = luminance(c);
      if (!(l > 0.0) || !std::isfinite(l)) continue;  // no light here (or not a number)
      log_sum += std::log(kLogDelta + l);
      scene.max = std::max<double>({scene.max, c.x, c.y, c.z});
      ++scene.pixels;
    }
  }
  if (scene.pixels > 0) scene.log_average = std::exp(log_sum / static_cast<double>(scene.pixels));
  return scene;
}

ToneMap adapt_tone_map(const ToneMapOptions& options, const SceneLuminance& scene, const ToneMap* previous,
                       double interval_s) {
  ToneMap tm;
  tm.op = options.op;
  if (options.op == ToneOperator::Exposure) {
    tm.exposure = options.exposure;
    return tm;
  }
  const bool adapted_before = previous != nullptr && previous->log_average_luminance > 0.f;
  double log_average = scene.log_average, white = scene.max;
  if (scene.pixels == 0) {
    if (!adapted_before) return tm;  // s = 1, no burn-out: nothing to adapt to yet
    log_average = previous->log_average_luminance;
    white = previous->white;
  } else if (adapted_before) {
    const double weight =
        options.adaptation_s > 0.0 ? 1.0 - std::exp(-std::max(0.0, interval_s) / options.adaptation_s) : 1.0;
    const auto towards = [&](double before, double now) {
      return std::exp(std::log(before) + weight * (std::log(now) - std::log(before)));
    };
    log_average = towards(previous->log_average_luminance, log_average);
    white = towards(std::max<double>(previous->white, kLogDelta), std::max(white, kLogDelta));
  }
  const double scale = options.key / log_average;
  const double scaled_white = std::max(1.0, scale * white);
  tm.exposure = static_cast<float>(scale);
  tm.inverse_white_squared = static_cast<float>(1.0 / (scaled_white * scaled_white));
  tm.log_average_luminance = static_cast<float>(log_average);
  tm.white = static_cast<float>(white);
  return tm;
}

}  // namespace relight::colormap
