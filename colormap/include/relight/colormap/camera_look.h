#pragma once
// The camera's look, put on the virtual layer: the virtual objects and their differential
// effects are rendered razor sharp and noise-free, the camera's image is soft, motion-blurred and
// noisy, and that difference reads as "pasted on" (dissertation §6.4: in its user study camera
// artefacts had the largest positive effect on perceived realism, Bradley-Terry +0.432; Klein &
// Murray 2010 for the method). The composite of composite.h, per pixel
//
//   out = c V + (1 - c)(L_cam + Delta)                         (eq. 5.1, coverage c)
//       = [c V] + (1 - c) L_cam + [(1 - c) Delta],
//
// becomes, with the camera's point spread B (defocus, then motion along each pixel's image
// motion over the exposure) applied to the rendered parts only (the camera image has it already):
//
//   out = B(c V) + (1 - B(c)) L_cam + B((1 - c) Delta) + n,
//
// and n, zero-mean noise of the camera's profile (camera_noise.h) at the pixel's intensity on the
// virtual share B(c): sigma_n = sigma(I) sqrt(1 - (1 - B(c))^2), so that a partly covered pixel,
// whose camera part already carries (1 - B(c)) of the camera's noise, ends with the camera's
// sigma. The noise is new every frame (seeded by the frame), never a fixed pattern.
//
// V and Delta are display-referred linear RGB: TM(L_rv) and TM(L_rv) - TM(L_r) for the plain
// composite, tau(TM(L_rv)) and the mapped delta_L for the colour-mapped one.
#include <cstdint>
#include <optional>
#include <string>

#include "relight/colormap/camera_blur.h"
#include "relight/colormap/camera_noise.h"
#include "relight/core/image.h"

namespace relight::colormap {

/// Which artefacts are put on the virtual layer (--camera-artefacts).
struct CameraArtefacts {
  bool blur = true;
  bool motion = true;
  bool noise = true;
  [[nodiscard]] bool any() const { return blur || motion || noise; }
  friend bool operator==(const CameraArtefacts&, const CameraArtefacts&) = default;
};
/// "all", "none" or a comma-separated subset of blur, motion, noise; throws relight::Error
/// naming the choices otherwise.
[[nodiscard]] CameraArtefacts parse_camera_artefacts(const std::string& text);
[[nodiscard]] std::string to_string(const CameraArtefacts& artefacts);

/// Pixels: longer image motion over one exposure is cut to this length (a pose jump, a frame
/// skipped: the blur would smear the object across the picture and cost its length per pixel).
inline constexpr float kMaxMotionPx = 64.f;

/// The image motion of each pixel over the exposure, in pixels, on a grid of `cell`-pixel cells
/// (camera motion moves the image smoothly; bilinear between cell centres).
struct MotionField {
  int cell = 8;
  Image<Float3> motion;  ///< per cell: (du, dv, 0); empty: no motion
  [[nodiscard]] bool empty() const { return motion.empty(); }
  /// The motion at pixel (row, col) of the full image.
  [[nodiscard]] Float3 at(float row, float col) const;
  /// The largest motion length of any cell, pixels.
  [[nodiscard]] float max_length() const;
};

/// What the camera does to an image, estimated per frame (render/dir/camera_look_stage.h).
struct CameraLook {
  CameraArtefacts artefacts;
  float blur_sigma_px = 0.f;  ///< the Gaussian added to the rendered layer (the camera's, less the render's own)
  BlurEstimate blur;          ///< the camera's point spread as estimated (smoothed over frames)
  MotionField motion;         ///< the image motion over the exposure
  NoiseProfile noise;         ///< the camera's noise (smoothed over frames)
  std::uint64_t seed = 0;     ///< this frame's noise
  static constexpr const char* type_name = "CameraLook";
};

/// The rendered parts of the composite above, premultiplied by coverage, in display-referred
/// linear RGB.
struct VirtualLayer {
  RadianceImage virtual_color;  ///< c V
  Image<float> coverage;        ///< c
  RadianceImage delta;          ///< (1 - c) Delta
};

/// The layer over the camera image, with the look's artefacts when `look` is given (and has any),
/// as 8-bit sRGB. Where the layer is zero (no coverage, no delta) and no artefact reaches, the
/// camera pixel is kept bit for bit. Throws relight::Error when the sizes differ.
[[nodiscard]] ColorImage composite_layer(const ColorImage& camera, VirtualLayer layer, const CameraLook* look,
                                         int threads = 0);

/// B of the composite: the defocus Gaussian of sigma_px, then the motion blur of `motion`, on the
/// layer's three parts, within the box around the pixels the layer touches (the rest of the image
/// is left alone). Exposed for tests.
void blur_layer(VirtualLayer& layer, float sigma_px, const MotionField* motion, int threads = 0);

}  // namespace relight::colormap
