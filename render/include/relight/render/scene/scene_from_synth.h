#pragma once
// The synthetic scene's exact geometry as the real part of an MrScene (ground-truth comparisons).
//
// Spheres and cylinders become triangle meshes with interpolated vertex normals; boxes and
// rectangles are exact. `segments` sets the tessellation (around a sphere's equator / a
// cylinder); 96 keeps the sphere's silhouette within 0.05 % of its radius. Tag decals are not
// modelled: their face keeps the object's material. Point lights become real point lights and
// the constant sky becomes the real environment.
#include "relight/render/scene/mr_scene.h"
#include "relight/synth/scene.h"

namespace relight::render {

struct TessellationOptions {
  int segments = 96;
};

[[nodiscard]] MrScene scene_from_synth(const synth::Scene& scene, const TessellationOptions& options = {});

/// The mesh of one shape (for tests and the procedural models): every triangle gets `material`.
[[nodiscard]] TriangleMesh tessellate(const synth::Shape& shape, std::uint32_t material,
                                      const TessellationOptions& options = {});

}  // namespace relight::render
