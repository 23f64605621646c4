#include "relight/lights/light_output.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

namespace relight {

namespace {

nlohmann::ordered_json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::uint8_t to_srgb8(float linear) {
  const float c = std::clamp(linear, 0.f, 1.f);
  const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
  return static_cast<std::uint8_t>(std::lround(encoded * 255.f));
}

float exposure_for(const RadianceImage& probe) {
  std::vector<float> lum;
  lum.reserve(probe.size());
  for (const Float3& p : probe.pixels()) {
    const float l = 0.2126f * p.x + 0.7152f * p.y + 0.0722f * p.z;
    if (l > 0.f && std::isfinite(l)) lum.push_back(l);
  }
  if (lum.empty()) return 1.f;
  const auto nth = lum.begin() + static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(lum.size() - 1));
  std::nth_element(lum.begin(), nth, lum.end());
  return 0.8f / *nth;
}

void draw_ring(ColorImage& image, double u, double v, double radius, Rgb8 colour) {
  const int steps = std::max(16, static_cast<int>(8 * radius));
  for (int k = 0; k < steps; ++k) {
    const double angle = 2.0 * 3.14159265358979 * k / steps;
    for (double r : {radius, radius + 1.0}) {
      const int col = static_cast<int>(std::lround(u + r * std::cos(angle)));
      const int row = static_cast<int>(std::lround(v + r * std::sin(angle)));
      if (image.in_bounds(row, col)) image(row, col) = colour;
    }
  }
}

}  // namespace

std::string lights_to_json(const LightSet& set) {
  nlohmann::ordered_json lights = nlohmann::ordered_json::array();
  for (const Light& light : set.lights) {
    nlohmann::ordered_json entry;
    entry["type"] = light.kind == LightKind::Directional ? "directional" : "point";
    if (light.kind == LightKind::Directional) entry["direction"] = vec(light.direction);
    else entry["position"] = vec(light.position);
    entry["power"] = vec(light.power);
    entry["real"] = light.real;
    lights.push_back(entry);
  }
  nlohmann::ordered_json root;
  root["count"] = set.lights.size();
  root["total_power"] = vec(total_power(set));
  root["irradiance_up"] = vec(irradiance(set, Eigen::Vector3d::UnitZ()));
  root["lights"] = lights;
  return root.dump(2) + "\n";
}

ColorImage light_preview(const RadianceImage& probe, const ProbeGeometry& geometry, const LightSet& set) {
  const float exposure = exposure_for(probe);
  ColorImage image(probe.width(), probe.height());
  for (int row = 0; row < probe.height(); ++row) {
    for (int col = 0; col < probe.width(); ++col) {
      const Float3& p = probe(row, col);
      image(row, col) = {to_srgb8(exposure * p.x), to_srgb8(exposure * p.y), to_srgb8(exposure * p.z)};
    }
  }
  std::vector<double> shares;
  double total = 0.0;
  for (const Light& light : set.lights) total += std::max(0.0, luminance(light.power));
  if (!(total > 0.0)) return image;
  std::vector<double> sorted;
  for (const Light& light : set.lights) sorted.push_back(luminance(light.power));
  std::sort(sorted.begin(), sorted.end(), std::greater<>());
  const double strong = sorted[std::min(sorted.size() - 1, sorted.size() / 10)];
  const double scale = 0.15 * std::min(probe.width(), probe.height());
  for (const Light& light : set.lights) {
    if (light.kind != LightKind::Directional) continue;
    const auto uv = geometry.project(light.direction);
    if (!uv) continue;
    const double share = std::max(0.0, luminance(light.power)) / total;
    const Rgb8 colour = luminance(light.power) >= strong ? Rgb8{255, 40, 40} : Rgb8{40, 255, 40};
    draw_ring(image, uv->x(), uv->y(), std::max(2.0, scale * std::sqrt(share)), colour);
  }
  return image;
}

}  // namespace relight
