#pragma once
// How soft the camera's image is: the standard deviation of a Gaussian point spread that its
// edges show, for blurring the virtual layer the same way (dissertation §6.4: camera artefacts on
// the virtual objects are what raised perceived realism most; Klein & Murray 2010).
//
// Method: gradient ratio of a re-blurred step edge (Zhuo & Sim, "Defocus map estimation from a
// single image", Pattern Recognition 2011). A step blurred by G_sigma has, at the edge,
//   |grad I| / |grad (G_s0 * I)| = R = sqrt(sigma^2 + s0^2) / sigma,   so sigma = s0 / sqrt(R^2 - 1).
// (Central differences measure the gradient over two pixels, a box of variance 1/3 that both
// gradients share, and both are taken on the image pre-blurred by p against noise, which would
// otherwise steepen the edge at the pixel alone: sigma^2 = s0^2 / (R^2 - 1) - 1/3 - p^2.) Computed on linear luminance
// (a blur happens to radiance, before the camera's transfer curve), at local maxima of the gradient along its direction
// with enough contrast and no clipped pixel nearby; the median over the edges is the estimate (texture and non-step
// edges scatter it). The estimate is the camera's whole point spread: optics, demosaicing and the pixel footprint.
//
// Motion blur widens the edges across the motion only. Given the image motion's direction,
// only edges whose gradient is nearly perpendicular to it (edges along the motion) take part, so
// the estimate is the defocus alone and motion blur is applied separately (camera_look.h).
#include <Eigen/Core>
#include <optional>

#include "relight/core/image.h"

namespace relight::colormap {

struct BlurEstimationOptions {
  double reblur_sigma = 1.0;    ///< s0, pixels
  double pre_blur_sigma = 0.8;  ///< pixels: both gradients on the image blurred by this (noise)
  double min_contrast = 0.04;   ///< linear luminance step across the edge (+-3 px), at least
  double max_sigma = 5.0;       ///< pixels: wider estimates are not steps (shading, soft shadows)
  int max_edges = 2000;         ///< candidate 2x2 blocks measured per image, at most (an even share)
  /// With a motion direction: |cos| between the edge's gradient and the motion, at most.
  double max_motion_cosine = 0.34;
};

struct BlurEstimate {
  double sigma_px = 0.0;  ///< the median point-spread sigma, pixels
  int edges = 0;          ///< edges it is the median of; 0: no estimate (sigma_px = 0)
  [[nodiscard]] bool valid() const { return edges > 0; }
};

/// `motion` (pixels, any length) excludes edges the camera's motion blurs, when given and
/// non-zero.
[[nodiscard]] BlurEstimate estimate_camera_blur(const ColorImage& image, const BlurEstimationOptions& options = {},
                                                std::optional<Eigen::Vector2f> motion = std::nullopt);

}  // namespace relight::colormap
