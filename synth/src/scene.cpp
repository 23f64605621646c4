#include "relight/synth/scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/core/error.h"

namespace relight::synth {

namespace {

using Eigen::Vector3d;

Rect wall(const Vector3d& centre, const Vector3d& normal, const Vector3d& u, double half_u) {
  return Rect{centre, normal, u, Vector3d::UnitZ(), half_u, 1.25};
}

void add_materials(Scene& scene) {
  // Six distinct diffuse colours (grey, wood, red, blue, yellow, black); floor and table share
  // the wood albedo but differ in gloss, the tag's white matches the walls.
  const Vector3d grey{0.70, 0.70, 0.68};
  const Vector3d wood{0.50, 0.34, 0.20};
  scene.materials = {
      {{wood, 0.05, 10.0}, "floor"},
      {{grey, 0.0, 1.0}, "wall"},
      {{wood, 0.15, 20.0}, "table"},
      {{{0.70, 0.12, 0.10}, 0.05, 10.0}, "red_paint"},
      {{{0.10, 0.18, 0.60}, 0.60, 80.0}, "glossy_blue"},
      {{{0.75, 0.62, 0.12}, 0.20, 30.0}, "yellow_plastic"},
      {{{0.03, 0.03, 0.03}, 0.0, 1.0}, "tag_black"},
      {{grey, 0.0, 1.0}, "tag_white"},
  };
}

void add_room(Scene& scene) {
  const int floor = scene.material_index("floor");
  const int walls = scene.material_index("wall");
  scene.objects.push_back({"floor", Rect{{0, 0, 0}, Vector3d::UnitZ(), Vector3d::UnitX(), Vector3d::UnitY(), 2.5, 2.5}, floor});
  scene.objects.push_back({"wall_east", wall({2.5, 0, 1.25}, -Vector3d::UnitX(), Vector3d::UnitY(), 2.5), walls});
  scene.objects.push_back({"wall_west", wall({-2.5, 0, 1.25}, Vector3d::UnitX(), Vector3d::UnitY(), 2.5), walls});
  scene.objects.push_back({"wall_north", wall({0, 2.5, 1.25}, -Vector3d::UnitY(), Vector3d::UnitX(), 2.5), walls});
  scene.objects.push_back({"wall_south", wall({0, -2.5, 1.25}, Vector3d::UnitY(), Vector3d::UnitX(), 2.5), walls});
}

void add_table(Scene& scene) {
  const int table = scene.material_index("table");
  scene.objects.push_back({"table_top", Box{{-0.6, -0.4, 0.72}, {0.6, 0.4, 0.75}}, table});
  int leg = 0;
  for (double x : {-0.55, 0.55}) {
    for (double y : {-0.35, 0.35}) {
      const Vector3d centre{x, y, 0.0};
      scene.objects.push_back({"table_leg_" + std::to_string(leg++),
                               Box{centre + Vector3d{-0.025, -0.025, 0}, centre + Vector3d{0.025, 0.025, 0.72}}, table});
    }
  }
}

void add_props(Scene& scene) {
  const int red = scene.material_index("red_paint");
  scene.objects.push_back({"box_on_table", Box{{0.22, 0.08, 0.75}, {0.42, 0.26, 0.87}}, red});
  scene.objects.push_back({"glossy_sphere", Sphere{{-0.35, 0.20, 0.85}, 0.10}, scene.material_index("glossy_blue")});
  scene.objects.push_back({"cylinder", Cylinder{{-0.05, 0.25, 0.75}, 0.05, 0.20}, scene.material_index("yellow_plastic")});
  scene.objects.push_back({"box_on_floor", Box{{-1.3, 0.6, 0.0}, {-0.9, 1.0, 0.35}}, red});
}

void add_tag(Scene& scene) {
  TagDecal tag;
  tag.code = kTag36h11Codes[0];
  tag.id = 0;
  tag.size = 0.16;
  tag.centre = {0.05, -0.15, 0.75};
  // Lying face up: tag-frame z (into the tag) must point down, so the image's "down" is world -y.
  tag.x_axis = Vector3d::UnitX();
  tag.y_axis = -Vector3d::UnitY();
  tag.object = scene.object_index("table_top");
  tag.black_material = scene.material_index("tag_black");
  tag.white_material = scene.material_index("tag_white");
  scene.tags.push_back(tag);
}

}  // namespace

std::vector<Eigen::Vector3d> TagDecal::corners_world() const {
  const double h = size / 2.0;
  std::vector<Eigen::Vector3d> corners;
  for (const auto& [a, b] : {std::pair{-h, h}, std::pair{h, h}, std::pair{h, -h}, std::pair{-h, -h}}) {
    corners.push_back(centre + a * x_axis + b * y_axis);
  }
  return corners;
}

int TagDecal::material_at(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d d = p - centre;
  // The 10x10 grid spans 5 cells either side of the centre.
  const double col = std::floor(d.dot(x_axis) / cell() + 5.0);
  const double row = std::floor(d.dot(y_axis) / cell() + 5.0);
  if (col < 0 || row < 0 || col > 9 || row > 9) return -1;
  return tag36h11_cell_is_white(code, static_cast<int>(row), static_cast<int>(col)) ? white_material : black_material;
}

int Scene::material_index(const std::string& name) const {
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name) return static_cast<int>(i);
  }
  throw Error("synthetic scene has no material named " + name);
}

int Scene::object_index(const std::string& name) const {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].name == name) return static_cast<int>(i);
  }
  throw Error("synthetic scene has no object named " + name);
}

double PointLight::falloff(const Eigen::Vector3d& from_light) const {
  if (!spot()) return 1.0;
  constexpr double kRadians = std::numbers::pi / 180.0;
  const double cos_outer = std::cos(cone_degrees * kRadians), cos_inner = std::cos(inner_degrees * kRadians);
  const double cosine = axis.dot(from_light);
  if (cosine >= cos_inner) return 1.0;
  if (cosine <= cos_outer) return 0.0;
  const double x = (cosine - cos_outer) / (cos_inner - cos_outer);
  return x * x * (3.0 - 2.0 * x);
}

Eigen::Vector3d unoccluded_irradiance(const Scene& scene, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  Eigen::Vector3d e = std::numbers::pi * scene.environment;
  for (const PointLight& light : scene.lights) {
    const Vector3d offset = light.position - point;
    const Vector3d to_light = offset.normalized();
    e += light.colour *
         (light.intensity * light.falloff(-to_light) * std::max(0.0, normal.dot(to_light)) / offset.squaredNorm());
  }
  return e;
}

Scene default_indoor_scene() {
  Scene scene;
  add_materials(scene);
  add_room(scene);
  add_table(scene);
  add_props(scene);
  add_tag(scene);
  scene.lights = {
      PointLight{{0.8, -0.6, 2.2}, {1.0, 0.93, 0.82}, 6.0, 0.04},
      PointLight{{-1.2, 1.0, 1.8}, {0.80, 0.88, 1.0}, 3.0, 0.04},
  };
  scene.environment = {0.15, 0.15, 0.15};
  scene.look_at = {0.0, 0.0, 0.75};
  scene.probe_position = {0.35, -0.25, 0.80};
  return scene;
}

bool tag36h11_cell_is_white(std::uint64_t code, int row, int col) {
  if (row <= 0 || col <= 0 || row >= 9 || col >= 9) return true;   // white margin
  if (row == 1 || col == 1 || row == 8 || col == 8) return false;  // black border
  // Data cells: AprilTag counts bit coordinates from the black border (1..6 = grid 2..7).
  for (std::size_t i = 0; i < kTag36h11BitX.size(); ++i) {
    if (kTag36h11BitX[i] + 1 == col && kTag36h11BitY[i] + 1 == row) return ((code >> (35 - i)) & 1u) != 0;
  }
  return false;
}

}  // namespace relight::synth
