#pragma once
// The synthetic scene's exact geometry as the real part of an MrScene (ground-truth comparisons).
//
// Spheres and cylinders become triangle meshes with interpolated vertex normals; boxes and
// rectangles are exact (render/scene/tessellation.h). Tag decals are not modelled: their face
// keeps the object's material. Point lights become real point lights and the constant sky
// becomes the real environment.
#include "relight/render/scene/mr_scene.h"
#include "relight/render/scene/tessellation.h"
#include "relight/synth/scene.h"

namespace relight::truth {

[[nodiscard]] render::MrScene scene_from_synth(const synth::Scene& scene,
                                               const render::TessellationOptions& options = {});

/// The mesh of one shape: every triangle gets `material`.
[[nodiscard]] render::TriangleMesh tessellate(const synth::Shape& shape, std::uint32_t material,
                                              const render::TessellationOptions& options = {});

}  // namespace relight::truth
