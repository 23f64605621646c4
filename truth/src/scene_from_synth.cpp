#include "relight/truth/scene_from_synth.h"

#include <type_traits>
#include <variant>

#include "relight/core/error.h"

namespace relight::truth {
namespace {

Eigen::Vector3f to_float(const Eigen::Vector3d& v) { return v.cast<float>(); }

}  // namespace

render::TriangleMesh tessellate(const synth::Shape& shape, std::uint32_t material,
                                const render::TessellationOptions& options) {
  if (options.segments < 3) throw Error("tessellation needs at least 3 segments");
  return std::visit(
      [&](const auto& s) -> render::TriangleMesh {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, synth::Sphere>)
          return render::tessellate_sphere(to_float(s.centre), static_cast<float>(s.radius), material, options);
        if constexpr (std::is_same_v<T, synth::Box>) return render::tessellate_box(to_float(s.min), to_float(s.max), material);
        if constexpr (std::is_same_v<T, synth::Rect>)
          return render::tessellate_rectangle(to_float(s.centre), to_float(s.normal), to_float(s.u) * static_cast<float>(s.half_u),
                                              to_float(s.v) * static_cast<float>(s.half_v), material);
        if constexpr (std::is_same_v<T, synth::Cylinder>)
          return render::tessellate_z_cylinder(to_float(s.base), static_cast<float>(s.radius),
                                               static_cast<float>(s.height), material, options);
      },
      shape);
}

render::MrScene scene_from_synth(const synth::Scene& scene, const render::TessellationOptions& options) {
  render::MrScene out;
  for (const synth::Material& m : scene.materials) out.add_material({m.cast<float>(), m.name, Eigen::Vector3f::Zero()});
  for (const synth::Object& object : scene.objects) {
    render::TriangleMesh mesh = tessellate(object.shape, static_cast<std::uint32_t>(object.material), options);
    mesh.name = object.name;
    mesh.real = true;
    out.meshes.push_back(std::move(mesh));
  }
  for (const synth::PointLight& light : scene.lights) {
    if (light.spot()) {
      out.lights.push_back(
          render::spot_light(to_float(light.position), to_float(light.axis), static_cast<float>(light.cone_degrees),
                             static_cast<float>(light.inner_degrees), to_float(light.colour * light.intensity), true));
      continue;
    }
    render::MrLight l;
    l.kind = render::LightKind::Point;
    l.position = to_float(light.position);
    l.intensity = to_float(light.colour * light.intensity);
    l.real = true;
    out.lights.push_back(l);
  }
  out.environment.radiance = to_float(scene.environment);
  return out;
}

}  // namespace relight::truth
