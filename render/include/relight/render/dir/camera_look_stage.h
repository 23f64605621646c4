#pragma once
// Frame-graph stage that measures the camera's look every frame, for the composites to put on
// the virtual layer (colormap/camera_look.h; dissertation §6.4, Klein & Murray 2010).
// Reads:  ColorImage "color" (the camera image), FrameInfo "frame" and its previous frame's
//         version (poses, timestamps), GBuffer "dir_gbuffer" (what each pixel sees, world frame),
//         the previous frame's CameraLook "camera_look" (temporal smoothing).
// Writes: CameraLook "camera_look":
//   - blur: the camera's point spread (camera_blur.h; edges along the image motion only, so motion
//     blur is not taken for defocus), smoothed over frames; the virtual layer gets the Gaussian of
//     sqrt(sigma_camera^2 - sigma_render^2), the render's own pixel footprint taken out;
//   - motion: each pixel's image motion between the previous pose and this one, scaled to the
//     exposure time (exposure / frame interval, at most 1; at most kMaxMotionPx long): the point the pixel sees is
//     projected into both cameras. None on the first frame, without poses, or across a gap of frames;
//   - noise: the camera's noise profile (camera_noise.h), smoothed over frames; the frame index
//     seeds the virtual layer's noise.
// With `alternate_estimates` (the default) the blur and the noise, after the first 8 frames, are
// each measured every second frame (blur on one, noise on the next) and carried over in between: both
// change slowly and are smoothed over frames anyway, and the two estimates were 40 % of the look's
// cost per frame (camera/artefacts_640x480).
#include <string>

#include "relight/colormap/camera_look.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/render/dir/gbuffer.h"

namespace relight::render {

struct CameraLookOptions {
  colormap::CameraArtefacts artefacts;
  double exposure_time_s = 1.0 / 30.0;  ///< the camera's exposure: how much of the motion one frame integrates
  double smoothing = 0.25;              ///< weight of this frame's estimates in the running ones
  bool alternate_estimates = true;      ///< blur and noise measured on alternate frames (see above)
  /// Variance (px^2) of the render's own point spread: DIR shades each pixel's centre (only the
  /// outlines' coverage is a 4x4 box, edge_coverage.h, whose 1/12 px^2 is left in the camera's).
  double render_variance_px2 = 0.0;
  colormap::BlurEstimationOptions blur;
  colormap::NoiseEstimationOptions noise;
};

/// The image motion over the exposure for every cell of `cell` pixels: the G-buffer's world point
/// of the cell's centre (the median depth of the seen cells where it sees nothing) projected by
/// both poses. Empty when either pose is missing or the timestamps do not give an interval of
/// (0, 0.25] s.
[[nodiscard]] colormap::MotionField image_motion(const GBuffer& gbuffer, const FrameInfo& frame,
                                                 const FrameInfo& previous, double exposure_time_s, int cell = 8);

/// What the stage measured over a run (report.json's "camera_look").
struct CameraLookSummary {
  colormap::CameraArtefacts artefacts;
  int frames = 0;
  double blur_sigma_px = 0.0;     ///< the camera's, last frame (smoothed)
  double applied_sigma_px = 0.0;  ///< the Gaussian the layer got, last frame
  int blur_edges = 0;             ///< edges of the last frame's estimate
  int blur_estimates = 0;         ///< frames that measured the blur (alternate_estimates: not all)
  int noise_estimates = 0;        ///< frames that measured the noise
  int frames_with_motion = 0;     ///< frames with a motion field
  double max_motion_px = 0.0;     ///< the longest image motion over an exposure
  colormap::NoiseProfile noise;   ///< last frame's (smoothed)
};

class CameraLookStage final : public Stage {
 public:
  explicit CameraLookStage(CameraLookOptions options) : options_(options) { summary_.artefacts = options.artefacts; }
  [[nodiscard]] std::string name() const override { return "camera_look"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const CameraLookSummary& summary() const { return summary_; }

 private:
  CameraLookOptions options_;
  CameraLookSummary summary_;
  Read<ColorImage> color_;
  Read<FrameInfo> frame_;
  ReadPrevious<FrameInfo> previous_frame_;
  Read<GBuffer> gbuffer_;
  ReadPrevious<colormap::CameraLook> previous_look_;
  Write<colormap::CameraLook> look_;
};

}  // namespace relight::render
