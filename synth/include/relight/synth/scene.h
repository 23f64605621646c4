#pragma once
// The synthetic indoor scene that serves as ground truth for every later test.
//
// World frame: z up (metres), floor at z = 0, the room spans x, y in [-2.5, 2.5] with walls
// 2.5 m high and no ceiling (rays that leave the room see the constant environment). The table
// top is at z = 0.75. Every object is an analytic primitive with a Phong material, so tests can
// compare rendered depth against closed-form intersections.
//
// Shading model (what the colour camera and the probe see), in linear radiance, with the Phong
// model of core/phong.h:
//   L = k_d * L_env                                  (ambient: unoccluded sky of radiance L_env)
//     + sum over visible lights of E * (k_d / pi + k_s * (n + 2) / (2 pi) * max(0, r.v)^n)
//   with irradiance E = colour * intensity * max(0, n.l) / d^2 (point light of radiant intensity
//   colour * intensity, W/sr per channel), r the mirror direction of l, v the view direction.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "relight/core/phong.h"
#include "relight/synth/tag36h11.h"

namespace relight::synth {

/// A named material: relight's Phong model (core/phong.h) in double, k_d in [0, 1].
struct Material : BasicPhong<double> {
  std::string name;
};

/// Sphere of the given centre and radius (metres).
struct Sphere {
  Eigen::Vector3d centre;
  double radius = 1.0;
};
/// Axis-aligned box [min, max].
struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
};
/// Finite rectangle: centre, unit normal, unit in-plane axes u and v, half extents along them.
struct Rect {
  Eigen::Vector3d centre;
  Eigen::Vector3d normal;
  Eigen::Vector3d u;
  Eigen::Vector3d v;
  double half_u = 1.0;
  double half_v = 1.0;
};
/// Closed cylinder whose axis is parallel to world z: base centre, radius, height.
struct Cylinder {
  Eigen::Vector3d base;
  double radius = 1.0;
  double height = 1.0;
};

using Shape = std::variant<Sphere, Box, Rect, Cylinder>;

/// One object. Material ids in LabelImages are material index + 1 (0 = nothing hit).
struct Object {
  std::string name;
  Shape shape;
  int material = 0;  ///< index into Scene::materials
};

/// Point light: radiant intensity colour * intensity (W/sr per channel) from `position`. It is a
/// point for shading and shadows; the light probe shows it as a sphere of `radius` whose
/// radiance colour * intensity / (pi radius^2) carries the same intensity.
/// With cone_degrees > 0 it is a spot light (a lamp): that intensity along `axis` and within
/// inner_degrees of it, fading to zero at cone_degrees with the smoothstep of the cosine, the
/// falloff relight's lights use (lights/light_set.h), so the ground truth and the renderer mean
/// the same lamp.
struct PointLight {
  Eigen::Vector3d position;
  Eigen::Vector3d colour{1, 1, 1};
  double intensity = 1.0;
  double radius = 0.04;
  Eigen::Vector3d axis{0, 0, -1};  ///< spot: unit, the direction it shines along
  double cone_degrees = 0.0;       ///< spot: half-angle where its light ends; 0: a point light
  double inner_degrees = 0.0;      ///< spot: half-angle of full intensity, (0, cone_degrees]

  [[nodiscard]] bool spot() const { return cone_degrees > 0.0; }
  /// The share of the intensity sent along unit direction `from_light` (1 for a point light).
  [[nodiscard]] double falloff(const Eigen::Vector3d& from_light) const;
};

/// An AprilTag printed onto a planar face of an object (a decal: it changes the material only).
/// Tag frame as AprilTag reports poses: x right and y down in the tag image, z into the tag.
/// `size` is the edge of the black square; the white margin adds one cell on each side.
struct TagDecal {
  std::uint64_t code = kTag36h11Codes[0];
  int id = 0;
  double size = 0.16;
  Eigen::Vector3d centre;
  Eigen::Vector3d x_axis;  ///< tag image right, in the world
  Eigen::Vector3d y_axis;  ///< tag image down, in the world
  int object = 0;          ///< the object it is printed on
  int black_material = 0;
  int white_material = 0;

  [[nodiscard]] Eigen::Vector3d z_axis() const { return x_axis.cross(y_axis); }
  [[nodiscard]] double cell() const { return size / 8.0; }
  /// Black-square corners in AprilTag's order: tag-frame (-s/2, +s/2), (+s/2, +s/2),
  /// (+s/2, -s/2), (-s/2, -s/2), i.e. counter-clockwise in the image starting bottom-left.
  [[nodiscard]] std::vector<Eigen::Vector3d> corners_world() const;
  /// Material index at world point p on the tag plane, or -1 outside the white margin.
  [[nodiscard]] int material_at(const Eigen::Vector3d& p) const;
};

struct Scene {
  std::vector<Material> materials;
  std::vector<Object> objects;
  std::vector<PointLight> lights;
  Eigen::Vector3d environment{0.15, 0.15, 0.15};  ///< constant sky radiance (linear RGB)
  std::vector<TagDecal> tags;
  Eigen::Vector3d look_at{0, 0, 0.75};  ///< what the camera trajectories aim at
  Eigen::Vector3d probe_position{0, 0, 1};  ///< where the light probe sits

  [[nodiscard]] int material_index(const std::string& name) const;  ///< throws relight::Error
  [[nodiscard]] int object_index(const std::string& name) const;    ///< throws relight::Error
};

/// Irradiance (RGB) on a surface at `point` of unit normal `normal` with nothing in the way: the
/// sky's pi * environment plus every light's E of the shading model above (the k_d / pi factor
/// turns it into the diffuse radiance the camera sees).
[[nodiscard]] Eigen::Vector3d unoccluded_irradiance(const Scene& scene, const Eigen::Vector3d& point,
                                                    const Eigen::Vector3d& normal);

/// Unit world up (+z).
inline Eigen::Vector3d world_up() { return Eigen::Vector3d::UnitZ(); }

/// The room: floor, four walls, a table (top 0.75 m) with a box, a glossy sphere, a cylinder
/// and the tag36h11 id 0 tag (0.16 m) on it, a box on the floor, two point lights.
Scene default_indoor_scene();

}  // namespace relight::synth
