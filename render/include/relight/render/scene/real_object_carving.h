#pragma once
// A pre-modelled real object (virtual_model.h add_real_model: a real mirror or glass) stands in
// for what the depth camera saw of it. The reconstruction's triangles there must go: a glass's or
// a mirror's depth is noise (light passes or bounces), and two coinciding surfaces - the model's
// specular one and the reconstruction's diffuse one - would fight over every ray.
//
// Reads a mesh (the reconstruction, world frame) and the object's placed meshes; writes the mesh
// without the triangles whose centre lies inside the object (odd crossings along a ray; the model
// must be closed, as check_model() warns for glass) or within `margin` of its surface (depth
// noise around it).
#include <span>

#include "relight/render/scene/mr_scene.h"

namespace relight::render {

/// Metres around a pre-modelled real object within which the reconstruction is taken for the
/// object's own noisy depth (a Kinect's depth noise at 1-2 m is a few millimetres).
inline constexpr float kRealObjectMargin = 0.01f;

/// Removes from `mesh` the triangles whose centre lies inside `object` or within `margin` metres
/// of its surface; returns how many.
std::size_t remove_triangles_within(TriangleMesh& mesh, std::span<const TriangleMesh> object, float margin);

}  // namespace relight::render
