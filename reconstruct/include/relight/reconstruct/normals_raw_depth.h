#pragma once
// Method 1 of Knecht 2013, §4.3.2: raw depth, raw position, temporally filtered normal.
//
//   positions = φ⁻¹(depth)                                  (raw, unfiltered; eq. 4.9)
//   Pass 1, on the previous frame's filtered normals N' (camera frame of that frame):
//     S(i,j)  = sum of valid N' over (i,j) and its 4-neighbourhood (eq. 4.1's average)
//     curv_H  = N'(i−1,j)·N'(i+1,j), curv_V = N'(i,j−1)·N'(i,j+1)                (eq. 4.1–4.2)
//     curv    = clamp(min(curv_H, curv_V), 0, 1)^128 (0 when a pair is missing)    (eq. 4.3)
//     at half resolution: texel (h, k) holds normalize(S(2h,2k) + S(2h,2k+1) + S(2h+1,2k) +
//     S(2h+1,2k+1)), the average over the 2×2 block of pixels that look it up, and the
//     curvature of pixel (2h, 2k); then a mip chain of `mip_levels` levels (2×2 means of the
//     valid texels: normal renormalised, curvature averaged). A texel that held only S(2h, 2k)
//     would describe the surface half a pixel up and left of the pixels that read it, and the
//     blend below would add that offset to the history every frame: on curved surfaces the
//     error then grows with the frame count.
//   Pass 2, per pixel with depth:
//     N = normals_from_positions with stride 4 (eq. 4.4–4.6, towards the camera), by default
//         with central differences V(i, j±4) where both sides continue the surface
//         (CrossNormalOptions::centred: the paper's forward differences tilt normals on curved
//         surfaces by half a stride's curvature);
//     p' = T_prev_from_current · p, where T_prev_from_current = camera_to_world_prev⁻¹ ·
//          camera_to_world_current maps current camera-frame points into the previous camera
//          frame; (u', v') = nearest pixel of φ(p') (floor(x + 0.5) per coordinate);
//     level = floor(curv(u', v') · (mip_levels − 1) + 0.5) (flat: coarse, edges: fine);
//     N_p = R_current_from_prev · A_level(u', v');
//     c_N = |N_p·N|, c = c_B·c_N + (1 − c_N)                                        (eq. 4.7–4.8)
//     c = 0 when there is no previous frame, (u', v') is outside it, N_p is missing, or
//           |z_prev(u', v') − p'.z| > disocclusion_m (disocclusion, moving objects);
//     normal = normalize(c·N_p + (1 − c)·N).
//   Holes (depth but no normal) get the normalised mean of their valid 4-neighbours.
//
// The CPU implementation resolves, in pass 1, the history normal N_p of every level-0 texel once
// (level choice, fallback to level 0, rotation), then computes positions, cross products, the
// blend and the hole filling in one pass over the rows (the neighbours' positions are re-derived
// from depth), eight pixels at a time with AVX2 where the CPU has it (chosen at run time; the
// build stays baseline x86-64), and the scalar loops otherwise. Both give bit-identical maps.
//
// Stage NormalsRawDepthCpuStage reads DepthMap "depth", FrameInfo "frame" (intrinsics,
// camera_to_world: identity when absent), and the previous frame's NormalMap "normals",
// PositionMap "positions" and FrameInfo "frame"; it writes NormalMap "normals" and PositionMap
// "positions".
//
// Method 2's "filtered normal" (§4.3.3: filtered depth, filtered position, filtered normal) is
// the same estimator on method 2's merged depth: with NormalsDepthInput::Filtered the stage reads
// DepthMap "depth_filtered" instead and is named "normals_filtered_depth". Measured on Kinect v1
// noise (320×240, tests/reconstruct/depth_warp_merge_test.cpp), it is what makes method 2 beat
// method 1 on flat regions (static camera 1.98° against 2.83°, orbit 3.49° against 4.60°), where
// the plain stride-1 cross product of the merged positions stays at 31°: averaging frames
// removes the sensor's random noise but not its disparity staircase, which the 8-pixel
// baseline and the temporal blend smooth out.
#include <memory>
#include <string>
#include <vector>

#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/core/rgbd_frame.h"
#include "relight/core/stage_backend.h"
#include "relight/reconstruct/normals_from_positions.h"

namespace relight::reconstruct {

struct NormalsRawDepthOptions {
  int stride = 4;                 ///< pixel distance of the cross-product differences (eq. 4.4–4.5)
  float blend_base = 0.9f;        ///< c_B of eq. 4.8
  float disocclusion_m = 0.1f;    ///< depth change that resets the history
  int mip_levels = 2;             ///< half and quarter resolution
  float max_jump_rel = 0.05f;     ///< discontinuity test of the cross products (relative to z)
  bool centred_differences = true;  ///< CrossNormalOptions::centred; false: the paper's forward ones
  int threads = 0;                ///< 0 = all cores
  bool simd = true;               ///< AVX2 loops where available; false: the scalar loops (same maps)
};

/// What method 1 keeps from the previous frame: its outputs and its pose.
struct NormalsHistory {
  const NormalMap& normals;
  const PositionMap& positions;
  Pose camera_to_world;
};

/// Method 1 on the CPU, keeping its scratch memory (the pass-1 pyramid, per-row hole lists)
/// between frames, so that a stream of same-sized frames allocates nothing after the first.
/// Create once, reuse every frame; not for concurrent calls.
class NormalsRawDepthCpu {
 public:
  NormalsRawDepthCpu();
  ~NormalsRawDepthCpu();
  NormalsRawDepthCpu(const NormalsRawDepthCpu&) = delete;
  NormalsRawDepthCpu& operator=(const NormalsRawDepthCpu&) = delete;

  /// normals_raw_depth (below) with this object's scratch memory.
  void run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
           const NormalsHistory* previous, const NormalsRawDepthOptions& options, PositionMap& positions,
           NormalMap& normals);
  /// normals_raw_depth_blend (below) with this object's scratch memory.
  void blend(const PinholeIntrinsics& intrinsics, const Pose& camera_to_world, const NormalsHistory* previous,
             const NormalsRawDepthOptions& options, const PositionMap& positions, NormalMap& normals);

 private:
  struct Workspace;
  std::unique_ptr<Workspace> workspace_;
};

/// One frame of method 1. `previous` is null on the first frame. Resizes the outputs.
/// (Allocates its scratch memory per call; NormalsRawDepthCpu keeps it.)
void normals_raw_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                       const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                       PositionMap& positions, NormalMap& normals);

/// The cross products of pass 2 as normals_from_positions / CrossNormalsVk options.
[[nodiscard]] CrossNormalOptions cross_normal_options(const NormalsRawDepthOptions& options);

/// Whether this CPU runs method 1's AVX2 loops (options.simd); otherwise the scalar loops run.
[[nodiscard]] bool normals_raw_depth_simd_available();

/// One level of the pass-1 pyramid: mean normal and curvature coefficient per texel.
struct NormalsPyramidLevel {
  Image<Float3> normal;
  Image<float> curvature;
};
/// Pass 1 (eq. 4.1–4.3) on the previous frame's normals: level 0 at half resolution, then up to
/// `levels` − 1 coarser levels (fewer when a side reaches 1 texel).
[[nodiscard]] std::vector<NormalsPyramidLevel> normals_history_pyramid(const NormalMap& previous, int levels,
                                                                       int threads = 0);

/// Everything of method 1 after the cross products: pass 1 on `previous`, pass 2's temporal
/// blend (eq. 4.7–4.8) and hole filling, applied in place to `normals`, which must hold this
/// frame's stride-s normals of `positions` (eq. 4.4–4.6). normals_raw_depth is positions_from_depth
/// + normals_from_positions + this; a backend that computes the cross products elsewhere
/// (CrossNormalsVk) finishes the frame with it. Throws LogicError when the shapes differ.
void normals_raw_depth_blend(const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                             const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                             const PositionMap& positions, NormalMap& normals);

/// Which depth the stage estimates from: the sensor's (method 1) or method 2's merged depth.
enum class NormalsDepthInput { Raw, Filtered };

/// What the CPU and Vulkan stages of method 1 share: the name, the buffers they declare (see the
/// header comment) and the poses of this and the previous frame (identity when a frame has none).
class NormalsRawDepthStageBase : public Stage {
 public:
  explicit NormalsRawDepthStageBase(NormalsRawDepthOptions options, NormalsDepthInput input = NormalsDepthInput::Raw)
      : options_(options), input_(input) {}
  [[nodiscard]] std::string name() const final;
  void declare(StageBuilder& builder) final;

 protected:
  [[nodiscard]] const NormalsRawDepthOptions& options() const { return options_; }
  [[nodiscard]] Pose camera_to_world(StageContext& context) const;
  [[nodiscard]] Pose previous_camera_to_world(StageContext& context) const;

  Read<DepthMap> depth_;
  Read<FrameInfo> frame_;
  ReadPrevious<NormalMap> previous_normals_;
  ReadPrevious<PositionMap> previous_positions_;
  ReadPrevious<FrameInfo> previous_frame_;
  Write<PositionMap> positions_;
  Write<NormalMap> normals_;

 private:
  NormalsRawDepthOptions options_;
  NormalsDepthInput input_;
};

/// Frame-graph stage of method 1 on the CPU (the reference).
class NormalsRawDepthCpuStage final : public NormalsRawDepthStageBase {
 public:
  explicit NormalsRawDepthCpuStage(NormalsRawDepthOptions options = {}, NormalsDepthInput input = NormalsDepthInput::Raw)
      : NormalsRawDepthStageBase(options, input) {}
  void run(StageContext& context) override;

 private:
  NormalsRawDepthCpu method_;
};

/// NormalsRawDepthCpuStage or NormalsRawDepthVkStage (normals_raw_depth_vk.h) for `backend`
/// (core/stage_backend.h); Backend::Vulkan requires a non-null `context`.
[[nodiscard]] std::unique_ptr<Stage> make_normals_raw_depth_stage(Backend backend, vk::VulkanContext* context,
                                                                  NormalsRawDepthOptions options = {},
                                                                  NormalsDepthInput input = NormalsDepthInput::Raw);

}  // namespace relight::reconstruct
