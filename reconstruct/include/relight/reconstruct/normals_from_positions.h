#pragma once
// Position maps from depth and normals from position maps by cross products: method 2's normal
// stage (Knecht 2013, §4.3.3), and the building block of method 1 (§4.3.2, stride 4) and of the
// "raw" normals every test compares against (stride 1 on raw depth).
//
// Definitions (both used by CPU and Vulkan code):
//   V(r, c) = φ⁻¹(c, r, depth(r, c)) = ((c − cx) z / fx, (r − cy) z / fy, z)          (eq. 4.9)
//   N(r, c) = normalize(d_col × d_row), d_col = V(r, c+s) − V(r, c), d_row = V(r+s, c) − V(r, c)
//             (eq. 4.4–4.6 with stride s; eq. of §4.3.3 with s = 1),
// oriented towards the camera (N·V < 0). Where the forward neighbour is missing or across a
// depth discontinuity (|Δz| > max_jump_rel · z) the backward difference V(r, c) − V(r, c−s) is
// used instead, so that object borders keep normals; with neither, the pixel has no normal.
// With `centred`, a pixel whose neighbours on both sides continue the surface uses the central
// difference V(r, c+s) − V(r, c−s) (and likewise for rows) instead: the forward difference
// describes the surface half a stride away, (r + s/2, c + s/2), which on curved surfaces tilts
// every normal by the curvature times s/2, and the longer baseline halves the effect of depth
// noise. Only the length of a difference changes with the choice of side, never the rule for
// borders, and a cross product's direction does not depend on those lengths.
//
// Stage NormalsFromPositionsCpuStage reads DepthMap "depth_filtered" and FrameInfo "frame"
// (intrinsics) and writes PositionMap "positions" and NormalMap "normals".
#include <memory>
#include <string>

#include "relight/core/buffers.h"
#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/rgbd_frame.h"
#include "relight/core/stage_backend.h"

namespace relight::reconstruct {

struct CrossNormalOptions {
  int stride = 1;              ///< s: pixel distance of the difference vectors
  float max_jump_rel = 0.05f;  ///< neighbour farther than this fraction of z: a discontinuity
  bool centred = false;        ///< central differences where both sides continue (see above)
  int threads = 0;             ///< 0 = all cores
};

/// V = φ⁻¹(depth); (0,0,0) where depth is invalid. Resizes `positions`.
void positions_from_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics, PositionMap& positions,
                          int threads = 0);
/// N from V as defined above. Resizes `normals`.
void normals_from_positions(const PositionMap& positions, NormalMap& normals, const CrossNormalOptions& options = {});

/// Buffer names of NormalsFromPositionsCpuStage.
struct NormalsFromPositionsBuffers {
  BufferName<DepthMap> depth = kDepthFiltered;
  BufferName<FrameInfo> frame = kFrame;
  BufferName<PositionMap> positions = kPositions;
  BufferName<NormalMap> normals = kNormals;
};

/// Method 2's normal stage (see the header comment for its buffers).
class NormalsFromPositionsCpuStage final : public Stage {
 public:
  using Buffers = NormalsFromPositionsBuffers;
  explicit NormalsFromPositionsCpuStage(CrossNormalOptions options = {}, Buffers buffers = {})
      : options_(options), buffers_(buffers) {}
  [[nodiscard]] std::string name() const override { return "normals_from_positions"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  CrossNormalOptions options_;
  Buffers buffers_;
  Read<DepthMap> depth_;
  Read<FrameInfo> frame_;
  Write<PositionMap> positions_;
  Write<NormalMap> normals_;
};

/// NormalsFromPositionsCpuStage or NormalsFromPositionsVkStage (cross_normals_vk.h) for `backend`
/// (core/stage_backend.h); Backend::Vulkan requires a non-null `context`.
[[nodiscard]] std::unique_ptr<Stage> make_normals_from_positions_stage(Backend backend, vk::VulkanContext* context,
                                                                       CrossNormalOptions options = {});

}  // namespace relight::reconstruct
