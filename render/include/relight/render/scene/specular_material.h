#pragma once
// Perfectly specular materials: mirrors, metals with a coloured reflectance and smooth glass
// (Knecht et al. 2013, "Reflective and refractive objects for mixed reality", §3-4; the
// dissertation's §5.3). A surface with such a material reflects and refracts only in the mirror
// and refraction directions (delta distributions); specular_bsdf.h samples them.
//
// - Conductor (a mirror or a polished metal): reflects with Schlick's Fresnel term of the
//   normal-incidence reflectance `reflectance` (a colour; 1 = a perfect mirror),
//   F(cos) = F0 + (1 - F0) (1 - cos)^5.
// - Dielectric (glass, water): reflects and refracts with the exact Fresnel equations of
//   unpolarised light at an interface of indices 1 | ior (not Schlick's fit: glass at grazing
//   angles and total internal reflection need the real curve), and absorbs inside by Beer-Lambert,
//   T(s) = attenuation_color^(s / attenuation_distance) per channel for a path of length s inside
//   (glTF's KHR_materials_volume; the paper's transmittance colour T_c "attenuated according to
//   the distance the light travelled through the object"). A dielectric mesh must be closed
//   with its triangles' normals pointing out (glTF's counter-clockwise winding): the winding
//   says whether a ray enters or leaves. Nested dielectrics are not modelled (a ray inside one
//   object is in air again when it leaves it).
//
// Which renderers see it: the differential path tracer (reference/path_tracer.h) renders these
// materials exactly, caustics included. DIR shades what they reflect and refract
// (dir/specular_gbuffer.h, dir/specular_shading.h) and their caustics (dir/caustic_photons.h:
// its shadow maps see glass as opaque, the photons bring the light through it back); the
// ray-traced VPL tracer follows light through them to the surface it reaches (caustic VPLs,
// vpl/vpl.h). Not yet: the rasterised RSM VPL source, which lights VPLs on them by their Phong
// fallback (PhongMaterial's k_d, k_s, n: for glTF the metallic-roughness mapping).

namespace relight::render {

enum class SpecularKind {
  None,        ///< not specular: the Phong model
  Conductor,   ///< mirror or metal
  Dielectric,  ///< glass
};

struct SpecularMaterial {
  SpecularKind kind = SpecularKind::None;
  /// Conductor: the reflectance at normal incidence F0 (linear RGB, each in [0, 1]).
  Eigen::Vector3f reflectance{1.f, 1.f, 1.f};
  /// Dielectric: the index of refraction inside (outside is 1).
  float ior = 1.5f;
  /// Dielectric: the share of light left per channel after attenuation_distance inside.
  Eigen::Vector3f attenuation_color{1.f, 1.f, 1.f};
  /// Dielectric: metres; infinity = clear (no absorption).
  float attenuation_distance = std::numeric_limits<float>::infinity();

  [[nodiscard]] bool specular() const { return kind != SpecularKind::None; }
};

/// A perfect or coloured mirror.
[[nodiscard]] inline SpecularMaterial conductor(const Eigen::Vector3f& reflectance = Eigen::Vector3f::Ones()) {
  SpecularMaterial m;
  m.kind = SpecularKind::Conductor;
  m.reflectance = reflectance;
  return m;
}

/// Glass of index `ior`, clear unless an attenuation colour and distance are given.
[[nodiscard]] inline SpecularMaterial dielectric(float ior,
                                                 const Eigen::Vector3f& attenuation_color = Eigen::Vector3f::Ones(),
                                                 float attenuation_distance = std::numeric_limits<float>::infinity()) {
  SpecularMaterial m;
  m.kind = SpecularKind::Dielectric;
  m.ior = ior;
  m.attenuation_color = attenuation_color;
  m.attenuation_distance = attenuation_distance;
  return m;
}

}  // namespace relight::render
