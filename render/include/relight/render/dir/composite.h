#pragma once
// The differential composite (Debevec 1998; Knecht's dissertation §5.2.1, eq. 5.1):
//
//   L_final = L_cam + TM(L_rv) - TM(L_r)          where the camera sees the real scene,
//   L_final = TM(L_rv)                            where a virtual object covers the pixel,
//
// blended by the virtual coverage c of the pixel: c TM(L_rv) + (1 - c)(L_cam + TM(L_rv) - TM(L_r)).
// L_cam is the camera image decoded to linear sRGB; TM is the shared tone-mapping operator of
// colormap/tone_map.h (what the camera does to radiance), so the differential is added in the
// camera's own linear space; the result is clamped to [0, 1] and sRGB-encoded to 8 bits.
//
// With fractional coverage (anti-aliased outlines, dir/edge_coverage.h) and `virtual_centre` (the
// pixels whose centre sample saw a virtual object, the G-buffer's), a partly covered pixel blends
// the virtual colour of its virtual-centre neighbours with the real differential of its
// real-centre ones (see separated_layer in composite.cpp).
//
// The multiplicative rule (Debevec 1998's alternative; TVCG 2013 eq. 2, alpha = CI / L_r) scales
// the camera instead of adding to it where the camera sees the real scene:
//
//   L_final = L_cam TM(L_rv) / TM(L_r)          (per channel; TM(L_r) < 1e-3: the additive rule)
//
// so a virtual shadow darkens the camera's own colour whatever hue the rendered real scene has:
// where the measured lights and albedos do not reproduce the camera (an orange probe over a
// neutral white desk, a clipped channel), the additive rule subtracts the render's hue and
// tints the shadow; the ratio only needs the render's relative change. The ratio is capped at
// kMaxCompositeRatio (light a virtual object adds to a dark real surface).
//
// Where the camera clipped (a channel at or above kClippedCode, core/pixel.h, as brdf/ marks it) neither
// rule can work with the camera's value: it stands for "at least 1", the render's TM(L_r) clips
// the same way, and a virtual shadow over a clipped table left the clipped channel at 1 while
// the others darkened (a saturated, hue-shifted shadow). There both composites, and both rules,
// first reconstruct the camera's unclipped value from the render - the clipped channels from
// L_r's chromaticity scaled to the camera's unclipped channels (all clipped: s L_r, s the tone
// map's scale, at least the camera's value) - and scale it by the rendered ratio L_rv / L_r, as
// the camera, not clipped, would see the change. Pixels the virtual objects leave unchanged keep
// the camera's value bit for bit.
//
// At the pixels of virtual mirrors and glass, both composites take the camera's own colours of
// what they reflect and refract where the camera sees it (back-projection, Knecht et al. 2013
// eqs. 6-11; specular_back_projection.h, CompositeOptions::back_projection), plus the change the
// virtual objects make to it.
//
// With a CameraLook both composites put the camera's blur, motion blur and noise on the rendered
// layer (colormap/camera_look.h, composite_layer): the virtual objects and the differential
// effects they cause, not the camera image, which has them already.
#include <array>

#include "relight/colormap/camera_look.h"
#include "relight/colormap/color_mapping.h"
#include "relight/colormap/tone_map.h"
#include "relight/core/image.h"
#include "relight/core/named_values.h"
#include "relight/render/differential_images.h"
#include "relight/render/dir/specular_back_projection.h"

namespace relight::render {

enum class CompositeRule { Additive, Multiplicative };
inline constexpr std::array<NamedValue<CompositeRule>, 2> kCompositeRuleNames{
    {{"additive", CompositeRule::Additive}, {"multiplicative", CompositeRule::Multiplicative}}};
inline constexpr float kMaxCompositeRatio = 8.f;

struct CompositeOptions {
  CompositeRule rule = CompositeRule::Additive;
  const colormap::CameraLook* look = nullptr;  ///< the camera's artefacts for the rendered layer
  const Mask* virtual_centre = nullptr;        ///< pixels whose centre sample saw a virtual object
  /// What mirrors and glass show (specular_back_projection.h): at their pixels the virtual
  /// colour is CI_bp + TM(L'_rv) - TM(L'_r) (the multiplicative rule: CI_bp TM(L'_rv) /
  /// TM(L'_r)) instead of TM(L_rv), L' being what L_rv and L_r hold there. None or empty: TM(L_rv).
  const SpecularBackProjection* back_projection = nullptr;
};

/// Throws relight::Error when the images differ in size.
[[nodiscard]] ColorImage differential_composite(const ColorImage& camera, const RadianceImage& real_virtual,
                                                const RadianceImage& real, const CoverageImage& virtual_coverage,
                                                const colormap::ToneMap& tone_map,
                                                const CompositeOptions& options = {});

/// The colour-mapped composite (eqs. 4.28-4.29 with the coverage blend above):
///   c tau(TM(L_rv)) + (1 - c)(L_cam + delta_L),   delta_L = tau(TM(L_rv)) - tau(TM(L_r)),
/// with delta_L and tau from a colour-mapping stage (colormap_stages.h); L_r for the clipped
/// camera pixels only. A pixel without coverage
/// and with a zero delta keeps the camera pixel bit for bit. Throws relight::Error on a size mismatch.
[[nodiscard]] ColorImage mapped_differential_composite(const ColorImage& camera, const RadianceImage& delta,
                                                       const RadianceImage& real_virtual, const RadianceImage& real,
                                                       const CoverageImage& virtual_coverage,
                                                       const colormap::ColorMapping& mapping,
                                                       const CompositeOptions& options = {});

}  // namespace relight::render
