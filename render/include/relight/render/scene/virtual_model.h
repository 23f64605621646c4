#pragma once
// Virtual objects: models loaded from OBJ/MTL or glTF 2.0 files (model_io.h) or built
// procedurally (procedural_models.h), and their placement in the scene.
//
// Axes: a model is stored as its file format has it - glTF is y-up by specification, and OBJ
// files are treated the same way (the common exporter default) - and turned z-up (relight's
// world convention) when placed: model (x, y, z) -> world (x, -z, y) before yaw, scale and
// translation. A model's origin should sit at the middle of its base, so that placing it at a
// point of the table stands it on the table.
#include <Eigen/Geometry>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "relight/render/scene/mr_scene.h"

namespace relight::render {

/// Meshes with triangle materials indexing VirtualModel::materials (not yet an MrScene's).
struct VirtualModel {
  std::string name;
  std::vector<PhongMaterial> materials;
  std::vector<TriangleMesh> meshes;
  /// What the loader read but cannot render as the file means it, one line each (an unsupported
  /// glTF extension, glass that is not a closed surface): the model is usable, the user is told.
  std::vector<std::string> warnings{};
};

/// Where a model goes: translation in the world (metres), the world direction its up axis
/// points along (world z for --place; a surface's normal for a placement on a real surface),
/// rotation about that axis (degrees), uniform scale.
struct Placement {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw_degrees = 0.0;
  double scale = 1.0;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< unit

  /// Parses "x,y,z[,yaw[,scale]]"; throws relight::Error naming the text otherwise.
  static Placement parse(const std::string& text);
  /// model (y-up) -> world transform: y-up to z-up, yaw about z, then the shortest rotation
  /// taking z to `up` (identity for up = z), scale, translation.
  [[nodiscard]] Eigen::Affine3d transform() const;
};

/// The world placement of each virtual object of a run, as a stage resolves them (placements
/// on a real surface are known only once a frame with a camera pose has been seen).
struct ObjectPlacements {
  bool resolved = false;                ///< false: no object is drawn yet
  std::vector<Placement> placements;    ///< one per object, in the objects' order
  static constexpr const char* type_name = "ObjectPlacements";
};

/// Adds the model to the scene as virtual meshes (materials appended, normals transformed).
void add_virtual_model(MrScene& scene, const VirtualModel& model, const Placement& placement);
/// Adds the model to the scene as real meshes (r = real): a pre-modelled object of the real
/// scene - a mirror or a glass, whose depth the camera cannot measure - that reflects, refracts
/// and casts caustics in both worlds of differential rendering (Knecht et al. 2013, Fig. 7's
/// real bottle). Its light is in the camera image already; what changes is what the virtual
/// objects and lights add to it. Returns the meshes it added (the end of scene.meshes; valid
/// until scene.meshes changes), e.g. for remove_triangles_within (real_object_carving.h).
std::span<const TriangleMesh> add_real_model(MrScene& scene, const VirtualModel& model, const Placement& placement);

/// Axis-aligned bounds of all vertices (for tests and reports).
[[nodiscard]] Eigen::AlignedBox3f bounds(const VirtualModel& model);

/// Throws relight::Error naming `file` when a mesh has a non-finite position or normal, a triangle
/// index past its vertices or a material index past the model's materials, or a material an
/// invalid specular part (specular_problem): what a loader checks before the model reaches the
/// renderer (which indexes without checking). Adds a warning for each glass mesh that is not a
/// closed surface: its rays enter and never leave, so it renders as a thin sheet at best.
void check_model(VirtualModel& model, const std::filesystem::path& file);

/// Area-weighted vertex normals from the triangles (for meshes that come without normals).
void compute_vertex_normals(TriangleMesh& mesh);

}  // namespace relight::render
