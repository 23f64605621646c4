#pragma once
// Temporal smoothing of the indirect light (Knecht's dissertation §5.2.9, eqs. 5.11-5.15): VPLs
// move from frame to frame (new light samples on a new reconstruction), and so does their light.
// Each pixel's indirect light is blended with last frame's at the same surface point:
//
//   eps_pos = |(dx_s, dy_s, dd) * w_p|        screen-space and depth distance between the point
//                                            reprojected into the last frame and what that
//                                            frame saw there (x, y in image fractions, d in the
//                                            Vulkan depth-buffer value of the G-buffer pass)
//   eps_n   = (1 - n . n_prev) * w_n
//   eps_ill = saturate(|I_new - I_prev|^3) * w_i
//   c       = saturate(1 - max(eps_pos, eps_n, eps_ill)) * c_B
//   I       = c I_prev + (1 - c) I_new
//
// with defaults w_p = (10, 10, 10000), w_n = 1, w_i = 0.025, c_B = 0.9. Disocclusions, moved
// virtual objects and fast changes fail the tests (c = 0) and take the new value.
//
// Reads this frame's G-buffer (world positions, normals, r(p)), camera and indirect light, and
// the TemporalHistory of the last frame; writes the smoothed indirect light and the new history.
#include <Eigen/Core>

#include "relight/render/dir/gbuffer.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/differential_images.h"
#include "relight/render/scene/mr_scene.h"

namespace relight::render {

struct TemporalOptions {
  Eigen::Vector3f w_p{10.f, 10.f, 10000.f};
  float w_n = 1.f;
  float w_i = 0.025f;
  float c_b = 0.9f;
  int threads = 0;  ///< 0: all cores (core/parallel.h)
};

struct TemporalHistory {
  static constexpr const char* type_name = "TemporalHistory";
  MrCamera camera;
  PositionMap positions;  ///< world frame; (0,0,0) where nothing was seen
  NormalMap normals;
  Mask virtual_surface;
  RadianceImage indirect_real_virtual;
  RadianceImage indirect_real;
};

/// Replaces the indirect part of `images` (and the totals that include it) by its blend with
/// `previous` (null: the first frame, nothing changes) and returns this frame's history.
TemporalHistory smooth_indirect(DifferentialImages& images, const GBuffer& gbuffer, const MrCamera& camera,
                                const TemporalHistory* previous, const TemporalOptions& options = {});

/// The value the G-buffer pass's depth buffer holds at camera-frame depth z (near 0.02 m, far
/// 200 m): what eq. 5.11's dd is measured in.
[[nodiscard]] float depth_buffer_value(float z);

}  // namespace relight::render
