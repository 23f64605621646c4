#pragma once
// Caustics in DIR (Knecht et al., TVCG 2013 §4.2.1 and §5.2, eqs. 12-14): the light a spot,
// point or directional light sends through mirrors and glass onto diffuse surfaces (LS+DE).
//
// Photons: from every light, rays aimed at the specular objects (the sampler of the path tracer's
// light tracing, but a rotated Hammersley set of directions per light where the tracer draws
// independent ones; the VPLs' photons take rotated Halton points), followed through their specular
// vertices (Fresnel-proportional choice, Beer-Lambert inside glass, up to `max_vertices`) to the
// first diffuse surface, where the photon is stored with its flux and incident direction; a ray
// whose first hit is not specular is direct light, which the shadow maps already give. Each photon
// path is traced in both worlds with the same random numbers: with the virtual objects (L_rv, every
// light) and without them (L_r, real lights; virtual meshes invisible), so the paper's real(ls,
// p_hit, p) of eq. 14 - a caustic reaches L_r only when the light, the specular object and the
// receiver are all real - follows from the geometry instead of being a flag.
//
// Density estimation: a G-buffer pixel at p with normal n reflects
//   L(p, wo) = sum over photons q within r_q of p (on p's side of the surface)
//              f(p; wi_q, wo) Phi_q 3 (1 - |q - p| / r_q) / (pi r_q^2)
// in the photons' world: each photon spreads its flux over a disc of its own radius r_q with a
// cone filter whose weights integrate to 1 (a sample-point estimator: the light a surface
// receives is the photons' whatever the radii). r_q adapts to the photons' density, as k-nearest-
// neighbour photon mapping does (Jensen 2001), so that a focused caustic stays sharp and the thin
// light a mirror spreads over a table is not noise: where `neighbours` photons of q's world
// crowd into less than the widest disc (`radius`), q's disc shrinks to hold about that many, down
// to `min_radius`. The density is counted per cell of `radius` over its 3 x 3 x 3 block (a
// surface crossing it covers about (3 radius)^2), the same for every photon of a cell and world,
// so that a photon traced alike in both worlds gets the same disc in both and cancels in
// L_rv - L_r. Measured (bench dir/specular_640x480, 16k photons per light, caustic_delta_rel_error,
// independent random directions): one disc of 1.5 cm 0.302; adaptive from 3 cm down to 4 mm with
// 32 neighbours 0.281 (64 neighbours 0.292; 2.5 cm to 3 mm with 48: 0.280; 2 cm to 4 mm with 64:
// 0.286); with the Hammersley and Halton directions 0.227 (one 3 cm disc 0.288). Where this
// departs from the paper: the paper rasterises photon G-buffers from each spot light and splats
// photon quads into a screen-space caustic buffer (CBuf); relight traces the photons (exact
// refraction, any light type, several specular vertices) and gathers them in world space, so the
// same photons light the primary G-buffer and the secondary G-buffers of reflections and
// refractions (caustics seen in a mirror, §4.2.1's last paragraph) without a buffer per view.
//
// Indirect light through mirrors and glass (L D S+ D E): the VPLs send photons at the specular
// objects the same way (trace_vpl_caustic_photons): a VPL lights a point behind a mirror or glass
// through its imperfect shadow map not at all (the object occludes it, as the paper's ISMs do),
// and the light the object passes on - the room that a mirror bottle reflects onto the table
// beside it, the light through a glass - reaches the table only along specular paths. The paper
// has no such term (its caustics start at spot lights); the path tracer does. Each photon picks
// a VPL in proportion to the flux it sends into the cone around the specular objects (luminance
// x the cone's solid angle x the best cosine inside it), a direction uniform in that cone, and
// carries Phi f_y(incident, w) cos(theta_y) / (pdf(w) N p(VPL)) in the VPL's worlds. Light from a
// diffuse source is smooth, so these photons are gathered over a wider disc (`vpl_radius`).
// Emitters (vpl.h) are left out: their lights send photons of their own above.
//
// Reads the MrScene through a RayTracer; writes CausticPhotons, which add_caustic_light()
// gathers into DifferentialImages for any G-buffer.
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "relight/render/differential_images.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/vpl/vpl.h"

namespace relight::render {

struct CausticPhoton {
  Eigen::Vector3f position;
  Eigen::Vector3f incident;  ///< unit, towards where the light came from
  Eigen::Vector3f normal;    ///< the receiving surface's, on the incident side
  Eigen::Vector3f flux;      ///< W
  bool real_world = false;   ///< traced without the virtual objects (L_r), else with them (L_rv)
  float radius = 0.f;        ///< metres: its disc (set by CausticPhotons from the density)
};

struct CausticOptions {
  /// Rays per light aimed at the specular objects; 0 = no caustics. Measured (bench
  /// dir/specular_640x480, mean of 3 seeds, caustic_delta_rel_error): 16k 0.227, 32k 0.204 for
  /// about 20 ms more of the frame; with vpl_radius 5 cm rather than 8, 32k gives 0.191.
  int photons_per_light = 32768;
  float radius = 0.03f;           ///< metres: the widest disc a photon is spread over (above)
  float min_radius = 0.004f;      ///< metres: the narrowest (= radius: every disc the same)
  int neighbours = 32;            ///< photons a disc holds where they crowd
  int max_vertices = 8;           ///< specular vertices one photon path may pass
  int vpl_photons = 16384;        ///< photons from all VPLs together (above); 0 = none
  float vpl_radius = 0.08f;       ///< metres: the disc their light is gathered over (fixed)
  std::uint64_t seed = 1;
};

/// How photons are spread over the surfaces they landed on (above).
struct PhotonKernel {
  float radius = 0.015f;      ///< the widest disc, and the grid's cell
  float min_radius = 0.015f;  ///< the narrowest
  int neighbours = 32;
};

/// The photons of one frame, each with its disc, indexed by a grid of `radius` cells for the
/// gather.
class CausticPhotons {
 public:
  CausticPhotons() = default;
  /// `indirect`: the photons of VPLs, whose light add_caustic_light() also counts in the
  /// images' indirect parts (for their temporal smoothing).
  CausticPhotons(std::vector<CausticPhoton> photons, const PhotonKernel& kernel, bool indirect = false);

  [[nodiscard]] const std::vector<CausticPhoton>& photons() const { return photons_; }
  [[nodiscard]] float radius() const { return radius_; }  ///< the widest disc
  [[nodiscard]] bool empty() const { return photons_.empty(); }
  [[nodiscard]] bool indirect() const { return indirect_; }
  /// Calls visit(photon) for every photon whose disc holds `point` (in either world).
  template <class Visit>
  void for_each_near(const Eigen::Vector3f& point, const Visit& visit) const;

 private:
  [[nodiscard]] std::int64_t key(int x, int y, int z) const;
  std::vector<CausticPhoton> photons_;
  float radius_ = 0.f;
  bool indirect_ = false;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
};

/// Traces the photons of every light of the tracer's scene (none without specular surfaces).
[[nodiscard]] CausticPhotons trace_caustic_photons(const RayTracer& tracer, const CausticOptions& options,
                                                   int threads = 0);

/// The photons that `vpls` send through the specular objects of the tracer's scene (above; none
/// without specular surfaces or VPLs).
[[nodiscard]] CausticPhotons trace_vpl_caustic_photons(const RayTracer& tracer, std::span<const Vpl> vpls,
                                                       const CausticOptions& options, int threads = 0);

/// Adds the caustic light that each pixel of `gbuffer` reflects towards its eye (`eyes`, or
/// `camera_centre` for all) to `images`' L_rv (photons of the virtual world) and, on real
/// surfaces, L_r (photons of the real world); `weights` (optional) scales it per pixel (a
/// secondary G-buffer's branch weight). The images' indirect parts (when they have them) gain the
/// light of indirect photons (the VPLs') only.
void add_caustic_light(DifferentialImages& images, const GBuffer& gbuffer, const MrScene& scene,
                       const CausticPhotons& photons, const Eigen::Vector3f& camera_centre,
                       const PositionMap* eyes = nullptr, const RadianceImage* weights = nullptr, int threads = 0);

template <class Visit>
void CausticPhotons::for_each_near(const Eigen::Vector3f& point, const Visit& visit) const {
  if (photons_.empty()) return;
  const Eigen::Vector3i cell = (point / radius_).array().floor().cast<int>();
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto found = cells_.find(key(cell.x() + dx, cell.y() + dy, cell.z() + dz));
        if (found == cells_.end()) continue;
        for (const std::uint32_t i : found->second)
          if ((photons_[i].position - point).squaredNorm() <= photons_[i].radius * photons_[i].radius)
            visit(photons_[i]);
      }
}

}  // namespace relight::render
