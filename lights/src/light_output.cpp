#include "relight/lights/light_output.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "relight/core/error.h"

namespace relight::lights {

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

const char* light_kind_name(LightKind kind) {
  switch (kind) {
    case LightKind::Directional: return "directional";
    case LightKind::Point: return "point";
    case LightKind::Spot: return "spot";
  }
  return "unknown";
}

std::string lights_to_json(const LightSet& set) {
  nlohmann::ordered_json lights = nlohmann::ordered_json::array();
  for (const Light& light : set.lights) {
    nlohmann::ordered_json entry;
    entry["type"] = std::string(light_kind_name(light.kind));
    if (light.kind == LightKind::Directional) entry["direction"] = vec(light.direction);
    else entry["position"] = vec(light.position);
    if (light.kind == LightKind::Spot) {
      entry["axis"] = vec(light.axis);
      entry["cone_degrees"] = light.cone_degrees;
      entry["inner_degrees"] = light.inner_degrees;
    }
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

namespace {

Eigen::Vector3d read_vec3(const nlohmann::json& entry, const char* key, const std::string& where) {
  if (!entry.contains(key) || !entry[key].is_array() || entry[key].size() != 3)
    throw Error(where + ": '" + key + "' must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    const nlohmann::json& x = entry[key][static_cast<std::size_t>(i)];
    if (!x.is_number() || !std::isfinite(x.get<double>())) throw Error(where + ": '" + key + "' must hold finite numbers");
    v[i] = x.get<double>();
  }
  return v;
}

/// A direction: any finite, non-zero vector, scaled to unit length. The stable norm, because
/// components near the largest double overflow the plain one (a direction of 1e300s became zero).
Eigen::Vector3d read_unit_vec3(const nlohmann::json& entry, const char* key, const std::string& where,
                               const std::string& what) {
  Eigen::Vector3d v = read_vec3(entry, key, where);
  if (!(v.stableNorm() >= 1e-9)) throw Error(where + ": " + what + " must not be zero");
  v.stableNormalize();
  return v;
}

}  // namespace

LightSet lights_from_json(const std::string& text, const std::string& source) {
  const nlohmann::json root = nlohmann::json::parse(text, nullptr, false);
  if (root.is_discarded()) throw Error(source + ": not valid JSON");
  if (!root.is_object() || !root.contains("lights") || !root["lights"].is_array())
    throw Error(source + ": expected an object with a \"lights\" array");
  LightSet set;
  for (std::size_t i = 0; i < root["lights"].size(); ++i) {
    const nlohmann::json& entry = root["lights"][i];
    const std::string where = source + ": light " + std::to_string(i);
    if (!entry.is_object() || !entry.contains("type") || !entry["type"].is_string())
      throw Error(where + ": needs a \"type\" of \"directional\", \"point\" or \"spot\"");
    Light light;
    std::string type = entry["type"].get<std::string>();
    if (type == "directional") {
      light.kind = LightKind::Directional;
      light.direction = read_unit_vec3(entry, "direction", where, "the direction");
    } else if (type == "point" || type == "spot") {
      light.kind = type == "point" ? LightKind::Point : LightKind::Spot;
      light.position = read_vec3(entry, "position", where);
    } else {
      throw Error(where + ": unknown type '" + type.append("' (directional, point or spot)"));
    }
    if (light.kind == LightKind::Spot) {
      light.axis = read_unit_vec3(entry, "axis", where, "the spot's axis");
      const auto degrees = [&](const char* key, double fallback) {
        if (!entry.contains(key)) return fallback;
        if (!entry[key].is_number()) throw Error(where + ": '" + key + "' must be a number of degrees");
        return entry[key].get<double>();
      };
      light.cone_degrees = degrees("cone_degrees", std::nan(""));
      if (!(light.cone_degrees > 0.0 && light.cone_degrees < 90.0))
        throw Error(where + ": a spot needs 'cone_degrees' in (0, 90)");
      light.inner_degrees = degrees("inner_degrees", 0.8 * light.cone_degrees);
      if (!(light.inner_degrees > 0.0 && light.inner_degrees <= light.cone_degrees))
        throw Error(where + ": 'inner_degrees' must be in (0, cone_degrees]");
    }
    light.power = read_vec3(entry, "power", where);
    if (light.power.minCoeff() < 0.0) throw Error(where + ": the power must not be negative");
    if (entry.contains("real")) {
      if (!entry["real"].is_boolean()) throw Error(where + ": 'real' must be true or false");
      light.real = entry["real"].get<bool>();
    }
    set.lights.push_back(light);
  }
  return set;
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

}  // namespace relight::lights
