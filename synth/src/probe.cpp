#include "relight/synth/probe.h"

#include <algorithm>
#include <limits>
#include <numbers>

#include "random.h"
#include "relight/core/parallel.h"

namespace relight::synth {

namespace {

using Eigen::Vector3d;

Float3 to_float3(const Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

Float3 probe_pixel(const Scene& scene, const LightProbe& probe, int row, int col) {
  const int s = std::max(1, probe.samples_per_axis);
  Vector3d sum = Vector3d::Zero();
  int inside = 0;
  for (int i = 0; i < s; ++i) {
    for (int j = 0; j < s; ++j) {
      const double u = col - 0.5 + (j + 0.5) / s, v = row - 0.5 + (i + 0.5) / s;
      const auto direction = probe.camera.unproject(u, v);
      if (!direction) continue;
      sum += incoming_radiance(scene, Ray{probe.position, (probe.probe_to_world * *direction).normalized()});
      ++inside;
    }
  }
  return inside > 0 ? to_float3(sum / inside) : Float3{};
}

}  // namespace

LightProbe default_probe(const Scene& scene) {
  LightProbe probe;
  probe.position = scene.probe_position;
  probe.probe_to_world = Eigen::Matrix3d::Identity();  // z-up world: x, y, z = world x, y, up
  return probe;
}

Vector3d incoming_radiance(const Scene& scene, const Ray& ray) {
  const auto hit = intersect(scene, ray);
  double nearest = hit ? hit->t : std::numeric_limits<double>::infinity();
  const PointLight* seen = nullptr;
  for (const PointLight& light : scene.lights) {
    if (auto emitter = intersect(Sphere{light.position, light.radius}, ray, 0.0, nearest)) {
      nearest = emitter->t;
      seen = &light;
    }
  }
  if (seen) {  // a lamp shows its emitter only to the directions it shines in
    return seen->colour *
           (seen->intensity * seen->falloff(-ray.direction) / (std::numbers::pi * seen->radius * seen->radius));
  }
  if (!hit) return scene.environment;
  const Vector3d normal = hit->normal.dot(ray.direction) > 0.0 ? Vector3d(-hit->normal) : hit->normal;
  const Material& material = scene.materials[static_cast<std::size_t>(material_at(scene, *hit))];
  return shade(scene, hit->point, normal, material, -ray.direction);
}

RadianceImage render_probe(const Scene& scene, const LightProbe& probe, int threads) {
  RadianceImage image(probe.camera.width, probe.camera.height);
  parallel_for_each_row(image.height(), threads, [&](int row) {
    for (int col = 0; col < image.width(); ++col) image(row, col) = probe_pixel(scene, probe, row, col);
  });
  return image;
}

RadianceImage add_probe_noise(RadianceImage probe, double sigma, std::uint64_t seed, std::uint64_t frame) {
  if (!(sigma > 0.0)) return probe;
  std::mt19937_64 rng(detail::stream_seed(seed, 0x9b0be, frame));  // a stream of its own: not the depth noise's
  const auto noisy = [&](float v) {
    return std::max(0.f, v * static_cast<float>(1.0 + sigma * detail::gaussian(rng)));
  };
  for (Float3& p : probe.pixels()) p = {noisy(p.x), noisy(p.y), noisy(p.z)};
  return probe;
}

}  // namespace relight::synth
