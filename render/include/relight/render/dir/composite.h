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
// With a CameraLook both composites put the camera's blur, motion blur and noise on the rendered
// layer (colormap/camera_look.h, composite_layer): the virtual objects and the differential
// effects they cause, not the camera image, which has them already.
#include "relight/colormap/camera_look.h"
#include "relight/colormap/color_mapping.h"
#include "relight/colormap/tone_map.h"
#include "relight/core/image.h"
#include "relight/render/differential_images.h"

namespace relight::render {

/// Throws relight::Error when the images differ in size.
[[nodiscard]] ColorImage differential_composite(const ColorImage& camera, const RadianceImage& real_virtual,
                                                const RadianceImage& real, const CoverageImage& virtual_coverage,
                                                const colormap::ToneMap& tone_map,
                                                const colormap::CameraLook* look = nullptr,
                                                const Mask* virtual_centre = nullptr);

/// The colour-mapped composite (eqs. 4.28-4.29 with the coverage blend above):
///   c tau(TM(L_rv)) + (1 - c)(L_cam + delta_L),   delta_L = tau(TM(L_rv)) - tau(TM(L_r)),
/// with delta_L and tau from a colour-mapping stage (colormap_stages.h). A pixel without coverage
/// and with a zero delta keeps the camera pixel bit for bit. Throws relight::Error on a size mismatch.
[[nodiscard]] ColorImage mapped_differential_composite(const ColorImage& camera, const RadianceImage& delta,
                                                       const RadianceImage& real_virtual,
                                                       const CoverageImage& virtual_coverage,
                                                       const colormap::ColorMapping& mapping,
                                                       const colormap::CameraLook* look = nullptr,
                                                       const Mask* virtual_centre = nullptr);

/// TM(L) as an 8-bit sRGB picture (for looking at L_rv or L_r on their own).
[[nodiscard]] ColorImage tone_mapped_preview(const RadianceImage& radiance, const colormap::ToneMap& tone_map);

}  // namespace relight::render
