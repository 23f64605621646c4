#pragma once
// What the renderers rely on in a model that load_model() accepted (they index without
// checking): every triangle refers to existing vertices and an existing material, normals and
// texture coordinates are one per vertex or none, and a texture samples to finite colours. A violation aborts, so that
// libFuzzer keeps the input. The model is then placed in a scene as `relight replay --object` does; MrScene::validate()
// may still reject it with relight::Error (non-finite material parameters), which is the renderer's clear answer.
#include <cstdlib>

#include "relight/core/error.h"
#include "relight/render/scene/virtual_model.h"

namespace relight::fuzz {

inline void check_loaded_model(const render::VirtualModel& model) {
  if (model.meshes.empty()) std::abort();
  for (const render::TriangleMesh& mesh : model.meshes) {
    if (mesh.triangle_material.size() != mesh.triangles.size()) std::abort();
    if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) std::abort();
    if (!mesh.texcoords.empty() && mesh.texcoords.size() != mesh.positions.size()) std::abort();
    for (const auto& triangle : mesh.triangles)
      for (const std::uint32_t v : triangle)
        if (v >= mesh.positions.size()) std::abort();
    for (const std::uint32_t m : mesh.triangle_material)
      if (m >= model.materials.size()) std::abort();
  }
  for (const render::PhongMaterial& m : model.materials)
    for (const render::Texture* t :
         {m.base_color.get(), m.emission_texture.get(), m.metallic_roughness_texture.get(), m.normal_texture.get()})
      if (t && (!t->sample(0.3f, 0.7f, 1.5f).allFinite() || !t->mean().allFinite())) std::abort();
  render::MrScene scene;
  render::add_virtual_model(scene, model, render::Placement{});
  try {
    scene.validate();
  } catch (const Error&) {
  }
}

}  // namespace relight::fuzz
