#pragma once
// Frame-graph stage of differential instant radiosity (dir_vk.h): every frame it builds the
// mixed-reality scene - the reconstruction's position map as the real mesh, the configured real
// and virtual lights, the configured virtual objects - generates the VPLs, renders L_rv and L_r
// and composites them into the camera image (composite.h, eq. 5.1).
//
// Reads:  FrameInfo "frame" (intrinsics, camera_to_world: identity when absent), ColorImage
//         "color", PositionMap "positions" and NormalMap "normals" (camera frame, reconstruct/),
//         and, when `materials_buffer` is set, brdf::Materials (the BRDF stages' clusters).
// Writes: ColorImage "composite", RadianceImage "L_rv" and "L_r", CoverageImage
//         "virtual_coverage", RadianceImage "L_rv_indirect" (the VPL part of L_rv, smoothed).
//
// With a Vulkan context it renders with DirRendererVk (made on the first frame, remade when the
// frame size changes); without one, with render_dir_cpu() (same algorithm, much slower).
// The indirect light is smoothed over time (temporal_smoothing.h) with the stage's own history
// of the last frame (G-buffer, camera, indirect light).
// Real surfaces take the material of their pixel's BRDF cluster; pixels without one (shadows,
// too dark to estimate) take the pixel-weighted mean of the clusters, and without any Materials
// every real surface is `reconstruction_material`. The real materials matter for the picture:
// the differential adds TM(L_rv) - TM(L_r) to the camera image, so a virtual shadow computed
// with a grey albedo on a brown table subtracts grey and tints the shadow orange.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "relight/brdf/materials.h"
#include "relight/colormap/tone_map.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/render/depth_mesh.h"
#include "relight/render/dir_vk.h"
#include "relight/render/temporal_smoothing.h"
#include "relight/render/virtual_model.h"
#include "relight/render/vpl.h"

namespace relight::render {

struct DirStageOptions {
  DirVkOptions renderer{};
  /// With VplBudget::ByPreviousFlux the stage feeds each frame's flux per light into the next.
  VplOptions vpls{.count = 64};
  DepthMeshOptions mesh{.stride = 2};
  PhongMaterial reconstruction_material{"reconstruction", {0.5f, 0.5f, 0.5f}, 0.f, 1.f, {0.f, 0.f, 0.f}};
  colormap::ToneMap tone_map{};
  std::string materials_buffer;  ///< empty: no Materials input
  bool temporal_smoothing = true;
  TemporalOptions temporal{};
};

/// What the stage adds to every frame's real geometry.
struct DirSceneContent {
  std::vector<MrLight> lights;  ///< real (measured) and virtual lights
  std::vector<std::pair<VirtualModel, Placement>> objects;
};

class DirStage final : public Stage {
 public:
  /// `context` may be null (CPU fallback); it must outlive the stage.
  DirStage(vk::VulkanContext* context, DirSceneContent content, DirStageOptions options = {});
  ~DirStage() override;

  [[nodiscard]] std::string name() const override { return "dir"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

  /// The scene of the last frame (for tests and reports).
  [[nodiscard]] const MrScene& last_scene() const { return scene_; }
  [[nodiscard]] std::size_t last_vpl_count() const { return vpl_count_; }

 private:
  void build_scene(const PositionMap& positions, const NormalMap& normals, const Pose& camera_to_world,
                   const brdf::Materials* materials);

  vk::VulkanContext* context_;
  DirSceneContent content_;
  DirStageOptions options_;
  std::unique_ptr<DirRendererVk> renderer_;
  std::pair<int, int> renderer_size_{0, 0};
  MrScene scene_;
  std::size_t vpl_count_ = 0;
  std::optional<TemporalHistory> history_;
  Read<FrameInfo> frame_;
  Read<ColorImage> color_;
  Read<PositionMap> positions_;
  Read<NormalMap> normals_;
  Read<brdf::Materials> materials_;
  Write<ColorImage> composite_;
  Write<RadianceImage> real_virtual_;
  Write<RadianceImage> real_;
  Write<CoverageImage> coverage_;
  Write<RadianceImage> indirect_;
};

}  // namespace relight::render
