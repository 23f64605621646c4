#include "relight/synth/raycast.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/core/parallel.h"

namespace relight::synth {

namespace {

using Eigen::Vector3d;

// Shadow rays start this far off the surface so that they do not hit it again.
constexpr double kSurfaceOffset = 1e-6;

std::optional<Hit> make_hit(const Ray& ray, double t, const Vector3d& normal) {
  return Hit{t, ray.origin + t * ray.direction, normal, -1};
}

std::optional<Hit> intersect_sphere(const Sphere& s, const Ray& ray, double t_min, double t_max) {
  const Vector3d oc = ray.origin - s.centre;
  const double b = oc.dot(ray.direction);
  const double disc = b * b - (oc.squaredNorm() - s.radius * s.radius);
  if (disc < 0.0) return std::nullopt;
  const double root = std::sqrt(disc);
  for (double t : {-b - root, -b + root}) {
    if (t > t_min && t < t_max) return make_hit(ray, t, (ray.origin + t * ray.direction - s.centre) / s.radius);
  }
  return std::nullopt;
}

std::optional<Hit> intersect_box(const Box& box, const Ray& ray, double t_min, double t_max) {
  double near = -std::numeric_limits<double>::infinity();
  double far = std::numeric_limits<double>::infinity();
  int near_axis = -1, far_axis = -1;
  double near_sign = 0.0, far_sign = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double o = ray.origin[axis], d = ray.direction[axis];
    if (std::abs(d) < 1e-15) {
      if (o < box.min[axis] || o > box.max[axis]) return std::nullopt;
      continue;
    }
    double t0 = (box.min[axis] - o) / d, t1 = (box.max[axis] - o) / d;
    double sign0 = -1.0;  // entering through the min face has an outward normal of -axis
    if (t0 > t1) {
      std::swap(t0, t1);
      sign0 = 1.0;
    }
    if (t0 > near) { near = t0; near_axis = axis; near_sign = sign0; }
    if (t1 < far) { far = t1; far_axis = axis; far_sign = -sign0; }
    if (near > far) return std::nullopt;
  }
  Vector3d normal = Vector3d::Zero();
  if (near > t_min && near < t_max && near_axis >= 0) {
    normal[near_axis] = near_sign;
    return make_hit(ray, near, normal);
  }
  if (far > t_min && far < t_max && far_axis >= 0) {
    normal[far_axis] = far_sign;
    return make_hit(ray, far, normal);
  }
  return std::nullopt;
}

std::optional<Hit> intersect_rect(const Rect& rect, const Ray& ray, double t_min, double t_max) {
  const double denominator = ray.direction.dot(rect.normal);
  if (std::abs(denominator) < 1e-15) return std::nullopt;
  const double t = (rect.centre - ray.origin).dot(rect.normal) / denominator;
  if (!(t > t_min && t < t_max)) return std::nullopt;
  const Vector3d local = ray.origin + t * ray.direction - rect.centre;
  if (std::abs(local.dot(rect.u)) > rect.half_u || std::abs(local.dot(rect.v)) > rect.half_v) return std::nullopt;
  return make_hit(ray, t, rect.normal);
}

std::optional<Hit> intersect_cylinder_side(const Cylinder& c, const Ray& ray, double t_min, double t_max) {
  const double dx = ray.direction.x(), dy = ray.direction.y();
  const double ox = ray.origin.x() - c.base.x(), oy = ray.origin.y() - c.base.y();
  const double a = dx * dx + dy * dy;
  if (a < 1e-18) return std::nullopt;
  const double b = ox * dx + oy * dy;
  const double disc = b * b - a * (ox * ox + oy * oy - c.radius * c.radius);
  if (disc < 0.0) return std::nullopt;
  const double root = std::sqrt(disc);
  for (double t : {(-b - root) / a, (-b + root) / a}) {
    if (!(t > t_min && t < t_max)) continue;
    const double z = ray.origin.z() + t * ray.direction.z() - c.base.z();
    if (z < 0.0 || z > c.height) continue;
    const Vector3d normal{(ox + t * dx) / c.radius, (oy + t * dy) / c.radius, 0.0};
    return make_hit(ray, t, normal);
  }
  return std::nullopt;
}

std::optional<Hit> intersect_cylinder(const Cylinder& c, const Ray& ray, double t_min, double t_max) {
  std::optional<Hit> best = intersect_cylinder_side(c, ray, t_min, t_max);
  if (std::abs(ray.direction.z()) < 1e-15) return best;
  for (double cap : {0.0, c.height}) {
    const double t = (c.base.z() + cap - ray.origin.z()) / ray.direction.z();
    const double limit = best ? best->t : t_max;
    if (!(t > t_min && t < limit)) continue;
    const Vector3d p = ray.origin + t * ray.direction;
    if (std::hypot(p.x() - c.base.x(), p.y() - c.base.y()) > c.radius) continue;
    best = make_hit(ray, t, Vector3d{0, 0, cap > 0.0 ? 1.0 : -1.0});
  }
  return best;
}

template <class Visit>
void for_each_hit_candidate(const Scene& scene, const Ray& ray, double t_min, double t_max, Visit&& visit) {
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    if (auto hit = intersect(scene.objects[i].shape, ray, t_min, t_max)) {
      hit->object = static_cast<int>(i);
      if (!visit(*hit)) return;
    }
  }
}

Vector3d to_vector(const Float3& f) { return {f.x, f.y, f.z}; }
Float3 to_float3(const Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

std::uint8_t to_byte(double encoded) {
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(encoded, 0.0, 1.0)));
}

}  // namespace

std::optional<Hit> intersect(const Shape& shape, const Ray& ray, double t_min, double t_max) {
  return std::visit(
      [&](const auto& s) -> std::optional<Hit> {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, Sphere>) return intersect_sphere(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<S, Box>) return intersect_box(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<S, Rect>) return intersect_rect(s, ray, t_min, t_max);
        if constexpr (std::is_same_v<S, Cylinder>) return intersect_cylinder(s, ray, t_min, t_max);
      },
      shape);
}

std::optional<Hit> intersect(const Scene& scene, const Ray& ray, double t_min, double t_max) {
  std::optional<Hit> best;
  for_each_hit_candidate(scene, ray, t_min, t_max, [&](const Hit& hit) {
    if (!best || hit.t < best->t) best = hit;
    t_max = best->t;
    return true;
  });
  return best;
}

bool occluded(const Scene& scene, const Vector3d& from, const Vector3d& to) {
  const Vector3d offset = to - from;
  const double distance = offset.norm();
  const Ray ray{from, offset / distance};
  bool blocked = false;
  for_each_hit_candidate(scene, ray, 0.0, distance * (1.0 - 1e-9), [&](const Hit&) {
    blocked = true;
    return false;
  });
  return blocked;
}

int material_at(const Scene& scene, const Hit& hit) {
  for (const TagDecal& tag : scene.tags) {
    if (tag.object != hit.object || hit.normal.dot(tag.z_axis()) > -0.999) continue;
    if (std::abs((hit.point - tag.centre).dot(tag.z_axis())) > 1e-6) continue;
    if (const int m = tag.material_at(hit.point); m >= 0) return m;
  }
  return scene.objects[static_cast<std::size_t>(hit.object)].material;
}

Vector3d shade(const Scene& scene, const Vector3d& point, const Vector3d& normal, const Material& material,
               const Vector3d& to_viewer) {
  constexpr double pi = std::numbers::pi;
  Vector3d radiance = material.kd.cwiseProduct(scene.environment);
  const Vector3d origin = point + kSurfaceOffset * normal;
  for (const PointLight& light : scene.lights) {
    const Vector3d offset = light.position - point;
    const double distance2 = offset.squaredNorm();
    const Vector3d l = offset / std::sqrt(distance2);
    const double cosine = normal.dot(l);
    const double falloff = light.falloff(-l);
    if (cosine <= 0.0 || falloff <= 0.0 || occluded(scene, origin, light.position)) continue;
    const Vector3d irradiance = light.colour * (light.intensity * falloff * cosine / distance2);
    const double specular = phong_specular(material.ks, material.n, phong_reflect(l, normal).dot(to_viewer));
    radiance += irradiance.cwiseProduct(material.kd / pi + Vector3d::Constant(specular));
  }
  return radiance;
}

namespace {

void render_pixel(const Scene& scene, const PinholeIntrinsics& intrinsics, const Pose& pose, int row, int col,
                  RenderedFrame& out) {
  const Vector3d direction_camera = intrinsics.ray(col, row).normalized();
  const Ray ray{pose.translation(), pose.linear() * direction_camera};
  const auto hit = intersect(scene, ray);
  if (!hit) {
    out.radiance(row, col) = to_float3(scene.environment);
    return;
  }
  const Vector3d normal = hit->normal.dot(ray.direction) > 0.0 ? Vector3d(-hit->normal) : hit->normal;
  const int m = material_at(scene, *hit);
  const Material& material = scene.materials[static_cast<std::size_t>(m)];
  out.depth(row, col) = static_cast<float>(hit->t * direction_camera.z());
  out.normals(row, col) = to_float3(pose.linear().transpose() * normal);
  out.albedo(row, col) = to_float3(material.kd);
  out.material(row, col) = static_cast<std::uint16_t>(m + 1);
  out.radiance(row, col) = to_float3(shade(scene, hit->point, normal, material, -ray.direction));
}

}  // namespace

RenderedFrame render_frame(const Scene& scene, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                           int threads) {
  const int w = intrinsics.width, h = intrinsics.height;
  RenderedFrame out{DepthMap(w, h), NormalMap(w, h), RadianceImage(w, h), LabelImage(w, h), RadianceImage(w, h)};
  parallel_for_each_row(h, threads, [&](int row) {
    for (int col = 0; col < w; ++col) render_pixel(scene, intrinsics, camera_to_world, row, col, out);
  });
  return out;
}

double srgb_encode(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double srgb_decode(double encoded) {
  encoded = std::clamp(encoded, 0.0, 1.0);
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

ColorImage encode_color(const RadianceImage& radiance, const ColorResponse& response) {
  ColorImage image(radiance.width(), radiance.height());
  const auto& g = response.gains;
  const double e = response.exposure;
  for (std::size_t i = 0; i < radiance.size(); ++i) {
    const Vector3d l = to_vector(radiance.pixels()[i]);
    image.pixels()[i] = {to_byte(srgb_encode(e * g[0] * l.x())), to_byte(srgb_encode(e * g[1] * l.y())),
                         to_byte(srgb_encode(e * g[2] * l.z()))};
  }
  return image;
}

ColorImage encode_albedo(const RadianceImage& albedo) { return encode_color(albedo); }

}  // namespace relight::synth
