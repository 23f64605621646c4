#pragma once
// The camera's own view of what mirrors and glass show (Knecht et al., TVCG 2013 §4.1.2-4.1.3,
// eqs. 6-11, after Grosch): where a reflected or refracted ray of a specular pixel ends on a real
// surface that the camera itself sees, that surface's colour is taken from the camera image
// (back-projection) rather than from its rendering, and only the virtual objects' change,
// Delta L' = L'_rv - L'_r, is added:
//
//   L'_final = CI_bp + Delta L',   CI_bp = sum over branches b of
//                                     w_b CI(q_b)        where v_b (q_b real and valid)
//                                     TM(w_b L_r(q_b))   otherwise (the rendered real light)
//
// w_b is the branch's weight (the paper's eta_1, eta_2 T_c; specular_gbuffer.h), q_b the surface
// it ends on and CI(x) the camera image where x projects. The validation v_b: q_b is real,
// projects inside the image, and no real surface lies between the camera and q_b (short of
// `depth_tolerance` of its distance, relative): the camera image shows that very point. The
// paper compares depths with the primary G-buffer instead; that G-buffer holds the virtual
// objects, which the camera image does not, so it rejected exactly the table behind a glass
// object - what its refraction shows most. A branch that leaves the scene takes
// TM(w_b L_env), the environment's radiance.
//
// Where this departs from the paper: the paper validates the pixel as a whole (CI_bp is all
// back-projection or all L'_r), with an exception for virtual refractive objects whose
// reflection is invalid; relight validates each branch on its own, so a glass pixel whose
// refraction is seen by the camera and whose reflection is not takes the camera for the one and
// the rendering for the other, which makes the paper's exception unnecessary. The paper's alpha'
// (eq. 11) is the multiplicative composite rule of composite.h applied to CI_bp.
//
// Reads SpecularGBuffers, the branches' rendered real light (shade_specular_from_maps), the
// scene's real layer (a RayTracer) and the camera; writes SpecularBackProjection, which the differential
// composites (composite.h) read to put CI_bp in place of the camera image at specular pixels.
#include "relight/core/image.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/dir/specular_gbuffer.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render {

struct BackProjectedBranch {
  RadianceImage weight;        ///< w_b, zero where the pixel has no such branch
  RadianceImage real;          ///< L_r of what the branch sees (unweighted)
  Image<Float3> camera_pixel;  ///< (x, y, 1): where q_b projects, where v_b holds; (0, 0, 0) elsewhere
};

struct SpecularBackProjection {
  Mask specular;  ///< empty when no pixel is specular
  BackProjectedBranch reflected, refracted;

  [[nodiscard]] bool empty() const { return specular.empty(); }
  static constexpr const char* type_name = "SpecularBackProjection";
};

inline constexpr float kBackProjectionDepthTolerance = 0.02f;

/// `reflected_real` and `refracted_real`: L_r of each branch's surface (SpecularLight).
[[nodiscard]] SpecularBackProjection back_project(const SpecularGBuffers& specular, const RadianceImage& reflected_real,
                                                  const RadianceImage& refracted_real, const RayTracer& tracer,
                                                  const MrCamera& camera,
                                                  float depth_tolerance = kBackProjectionDepthTolerance);

/// CI_bp at pixel `index` (a specular one) in the camera's linear space: `camera_linear(x, y)`
/// is the camera image's decoded colour there (bilinear), `tone_map(L)` the composite's operator.
template <class CameraAt, class ToneMap>
[[nodiscard]] Float3 back_projected_camera(const SpecularBackProjection& view, std::size_t index,
                                           const CameraAt& camera_linear, const ToneMap& tone_map) {
  Float3 sum;
  for (const BackProjectedBranch* branch : {&view.reflected, &view.refracted}) {
    const Float3& w = branch->weight.pixels()[index];
    if (w == Float3{}) continue;
    const Float3& source = branch->camera_pixel.pixels()[index];
    if (source.z > 0.f) {
      const Float3 seen = camera_linear(source.x, source.y);
      sum += Float3{w.x * seen.x, w.y * seen.y, w.z * seen.z};
    } else {
      const Float3& r = branch->real.pixels()[index];
      sum += tone_map(Float3{w.x * r.x, w.y * r.y, w.z * r.z});
    }
  }
  return sum;
}

}  // namespace relight::render
