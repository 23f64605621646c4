#pragma once
// Method 2 of Knecht 2013, §4.3.3, first half: temporally filtered depth by forward warping.
//
// Warp (previous filtered depth → current view):
//   the previous depth is a vertex grid mesh (two triangles per 2×2 pixel quad);
//   p      = φ⁻¹(c, r, depth_prev(r, c))                 previous camera frame       (eq. 4.9)
//   p̂      = T_current_from_prev · p, T_current_from_prev = camera_to_world_current⁻¹ ·
//            camera_to_world_prev (camera_to_world maps camera-frame points into the world, so
//            this takes previous-camera points to the world and then into the current camera;
//            it is the dissertation's T_warp of eq. 4.10–4.11 written for camera-to-world poses)
//   depth  = φ(p̂).z                                                                  (eq. 4.12)
//   Triangles are rasterised at pixel centres (inclusive edges) with a z-test; 1/z is
//   interpolated linearly in screen space, which is exact for planar triangles. Triangles with a
//   missing vertex, or whose vertex depths differ by more than max_edge_m + max_edge_rel · z
//   (mesh edges across depth discontinuities), are discarded. A covered pixel carries the
//   smallest weight of its triangle's vertices.
// Merge (per pixel, new raw depth d with warped depth d_w and weight w), as KinectFusion does:
//   both valid, |d − d_w| ≤ τ(d) = merge_threshold_m + 3 σ_z(d)  → (w d_w + d)/(w + 1), w' = min(w + 1, max_weight)
//   both valid, farther apart (disocclusion, motion)               → d, w' = 1
//   only d valid → d, w' = 1;   only d_w valid → d_w, w' = w − 1 (history fades out: 0 = missing)
//   σ_z(z) = 0.0012 + 0.0019 (z − 0.4)² is the Kinect v1 axial noise (Nguyen et al. 2012).
//
// Stage DepthWarpMergeCpuStage reads DepthMap "depth", FrameInfo "frame" (intrinsics,
// camera_to_world: identity when absent) and the previous frame's DepthMap "depth_filtered",
// DepthWeightMap "depth_weight" and FrameInfo "frame"; it writes DepthMap "depth_filtered" and
// DepthWeightMap "depth_weight".
#include <memory>
#include <string>

#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/core/rgbd_frame.h"
#include "relight/core/stage_backend.h"

namespace relight::reconstruct {

/// Per-pixel count of the frames averaged into "depth_filtered" (0 = no depth).
struct DepthWeightMap : Image<float> {
  using Image<float>::Image;
  static constexpr const char* type_name = "DepthWeightMap";
};

struct DepthWarpMergeOptions {
  float max_edge_m = 0.05f;        ///< mesh edges across larger depth jumps are not rasterised
  float max_edge_rel = 0.03f;      ///< ... plus this fraction of the depth
  float merge_threshold_m = 0.05f; ///< τ's constant part
  float max_weight = 30.f;         ///< cap of the running average's weight
  int threads = 0;                 ///< 0 = all cores
};

/// Forward-warps the previous filtered depth and weight into the current view. Resizes outputs.
void warp_depth(const DepthMap& previous_depth, const DepthWeightMap& previous_weight,
                const PinholeIntrinsics& intrinsics, const Pose& current_from_prev,
                const DepthWarpMergeOptions& options, DepthMap& warped, DepthWeightMap& warped_weight);

/// Merges new raw depth with the warped history (rules above). Resizes outputs.
void merge_depth(const DepthMap& depth, const DepthMap& warped, const DepthWeightMap& warped_weight,
                 const DepthWarpMergeOptions& options, DepthMap& merged, DepthWeightMap& merged_weight);

/// What the CPU and Vulkan stages of method 2's warp and merge share: the buffers (header
/// comment) and how the previous frame's buffers and poses become the warp's inputs (identity
/// poses when a frame has none; no history when the previous depth is missing or differs in
/// shape). Subclasses only warp and merge.
class DepthWarpMergeStageBase : public Stage {
 public:
  explicit DepthWarpMergeStageBase(DepthWarpMergeOptions options) : options_(options) {}
  [[nodiscard]] std::string name() const final { return "depth_warp_merge"; }
  void declare(StageBuilder& builder) final;

 protected:
  [[nodiscard]] const DepthWarpMergeOptions& options() const { return options_; }
  /// T_current_from_prev of this frame (identity without poses).
  [[nodiscard]] Pose current_from_previous(StageContext& context);

  DepthWarpMergeOptions options_;
  Read<DepthMap> depth_;
  Read<FrameInfo> frame_;
  ReadPrevious<DepthMap> previous_depth_;
  ReadPrevious<DepthWeightMap> previous_weight_;
  ReadPrevious<FrameInfo> previous_frame_;
  Write<DepthMap> filtered_;
  Write<DepthWeightMap> weight_;
};

/// Frame-graph stage of method 2's warp and merge on the CPU (the reference).
class DepthWarpMergeCpuStage final : public DepthWarpMergeStageBase {
 public:
  explicit DepthWarpMergeCpuStage(DepthWarpMergeOptions options = {}) : DepthWarpMergeStageBase(options) {}
  void run(StageContext& context) override;

 private:
  DepthMap warped_;              // scratch, kept to avoid reallocating every frame
  DepthWeightMap warped_weight_;
};

/// DepthWarpMergeCpuStage or DepthWarpMergeVkStage (depth_warp_merge_vk.h) for `backend`
/// (core/stage_backend.h); Backend::Vulkan requires a non-null `context`.
[[nodiscard]] std::unique_ptr<Stage> make_depth_warp_merge_stage(Backend backend, vk::VulkanContext* context,
                                                                 DepthWarpMergeOptions options = {});

}  // namespace relight::reconstruct
