#pragma once
// Differential instant radiosity (dir_vk.h) as frame-graph stages, one per step, so that the
// graph times each step and keeps each step's output (add_dir_stages() adds all six, and camera_look when asked):
//
//   mr_scene                 reads  FrameInfo "frame" (camera_to_world: identity when absent),
//                                   PositionMap "positions" and NormalMap "normals" (camera frame,
//                                   reconstruct/), brdf::Materials when `materials_buffer` is set,
//                                   ObjectPlacements when `placements_buffer` is set,
//                                   lights::LightSet when `real_lights_buffer` is set (its
//                                   directional lights within `merge_lights_degrees` merged)
//                            writes MrScene "mr_scene": the reconstruction's position map as the
//                                   real mesh (and on a wider grid as MrScene::coarse_real_meshes),
//                                   that frame's real lights (when set) and the
//                                   configured real and virtual lights, the
//                                   configured virtual objects (at the placements of that
//                                   buffer when set, none while it is unresolved); with
//                                   EnvironmentLight::Vpls every directional light reaches the
//                                   scene through its emitter VPL (MrLight::through_vpl)
//   vpls                     reads  MrScene "mr_scene"; with VplBudget::ByPreviousFlux or
//                                   BounceMethod::PreviousFrame also the previous frame's VplSet
//                                   "vpls" (its flux per light; the VPLs the multiple-bounce light
//                                   source continues, Knecht 2010 §4.3)
//                            writes VplSet "vpls" (vpl.h), traced onto MrScene::coarse_real_meshes
//                                   in place of the real meshes when the scene has them
//   dir                      reads  FrameInfo "frame", ColorImage "color" and PositionMap
//                                   "positions" (the image size, which they must share),
//                                   MrScene "mr_scene", VplSet "vpls"; when `albedo_buffers` is
//                                   set, its RadianceImage (per-pixel k_d, "kd") and Mask
//                                   ("kd_valid", camera_albedo.h)
//                            writes DifferentialImages "dir_images" (L_rv, L_r, coverage and
//                                   their indirect parts, one shading pass; the coverage
//                                   fractional at outlines, edge_coverage.h; at mirrors and
//                                   glass what they reflect and refract, specular_shading.h),
//                                   SpecularBackProjection "specular_back_projection" (empty
//                                   without mirrors and glass) and GBuffer "dir_gbuffer"
//   indirect_smoothing       reads  DifferentialImages "dir_images", GBuffer "dir_gbuffer",
//                                   FrameInfo "frame"
//                            writes RadianceImage "L_rv", "L_r", "L_rv_indirect" (the VPL part
//                                   of L_rv) and CoverageImage "virtual_coverage", the indirect
//                                   light smoothed over time (temporal_smoothing.h, eq.
//                                   5.11-5.15); with it on, also TemporalHistory
//                                   "indirect_history" (G-buffer, camera, indirect light), whose
//                                   previous frame's version it reads; unchanged when off
//   tone_map                 reads  RadianceImage "L_rv", FrameInfo "frame" (Reinhard only)
//                            writes colormap::ToneMap "tone_map" (colormap/tone_map_stage.h)
//   differential_composite   reads  ColorImage "color", RadianceImage "L_rv", "L_r",
//                                   CoverageImage "virtual_coverage", GBuffer "dir_gbuffer"
//                                   (which pixel centres are virtual), SpecularBackProjection
//                                   "specular_back_projection", colormap::ToneMap
//                                   "tone_map"; with `camera_look` also
//                                   colormap::CameraLook "camera_look" (camera_look_stage.h)
//                            writes ColorImage "composite" (composite.h, eq. 5.1; empty on the frames
//                                   DirStageOptions::composite_frames leaves out)
//
// With a Vulkan context `dir` renders with DirRendererVk (made on the first frame, remade when
// the frame size changes); without one, with render_dir_cpu() (same algorithm, much slower).
// Real surfaces take the material of their pixel's BRDF cluster; pixels without one (shadows,
// too dark to estimate) take the pixel-weighted mean of the clusters, and without any Materials
// every real surface is `reconstruction_material`. The real materials matter for the picture:
// the differential adds TM(L_rv) - TM(L_r) to the camera image, so a virtual shadow computed
// with a grey albedo on a brown table subtracts grey and tints the shadow orange.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "relight/brdf/materials.h"
#include "relight/colormap/adaptive_tone_map.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/named_values.h"
#include "relight/core/rgbd_frame.h"
#include "relight/core/stage_backend.h"
#include "relight/lights/light_set.h"
#include "relight/render/buffers.h"
#include "relight/render/dir/camera_look_stage.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/dir_vk.h"
#include "relight/render/dir/temporal_smoothing.h"
#include "relight/render/scene/depth_mesh.h"
#include "relight/render/scene/virtual_model.h"
#include "relight/render/vpl/cone_search_vk.h"
#include "relight/render/vpl/reflective_shadow_map_vk.h"
#include "relight/render/vpl/vpl.h"

namespace relight::colormap {
class ToneMapStage;
}  // namespace relight::colormap

namespace relight::render {

class VplStage;

/// How the directional lights of the environment (the probe's lights) light the scene:
///   Directional  through the direct pass, each with two orthographic shadow maps (real and
///                virtual layer) rasterised every frame;
///   Vpls         as emitter VPLs shadowed through their ISMs, like every other VPL (Knecht et
///                al. 2010 §3.6 and §5.2, dissertation §5.2.7; vpl.h says where ours depart): far
///                cheaper per light, so the probe can give many more of them, with the
///                interleaved VPLs' softer shadows.
enum class EnvironmentLight { Directional, Vpls };
inline constexpr std::array<NamedValue<EnvironmentLight>, 2> kEnvironmentLightNames{
    {{"directional", EnvironmentLight::Directional}, {"vpls", EnvironmentLight::Vpls}}};

/// A per-pixel k_d of the real surfaces and where it is valid (brdf/'s diffuse estimate).
struct RealAlbedoBuffers {
  BufferName<RadianceImage> albedo = kKd;
  BufferName<Mask> valid = kKdValid;
};

struct DirStageOptions {
  DirRenderOptions renderer{};
  VplOptions vpls{.count = 64};
  /// The reconstruction's rendered mesh. MrSceneStage raises its edge rule to keep surfaces up
  /// to a 75-degree slant at the frame's focal length (4 pixel footprints per grid step), which
  /// matters below 640 across: at 160 x 120 the default rule dropped a table top seen from 1.5 m.
  DepthMeshOptions mesh{.stride = 2};
  /// The grid stride of the reconstruction's coarse copy (MrScene::coarse_real_meshes: the
  /// occluders of the shadow-mapped lights' maps and the surfaces VPLs land on), in pixels of a
  /// 640-pixel-wide image (scaled with the width: the same angular spacing at every resolution,
  /// 2 at 320); when that is at or below mesh.stride, there is no coarse copy. Its triangles are
  /// still about as fine as a shadow map's texels over a room (4 px at 525 px focal length:
  /// 7.6 mm at 1 m, 2.3 cm at 3 m; a 256-texel view, replay's, over a 6 m room: 2.3 cm), and a
  /// quarter as many, which is what rasterising them and building the VPLs' ray-tracing BVH
  /// cost on a CPU: pipeline/replay_640x480's shadow maps 65-95 -> 30-57 ms and its vpls stage
  /// 22-25 -> 6-7 ms per frame. Its edge rule (depth_mesh.h) grows with its grid step, so it
  /// drops the slopes the rendered mesh drops (depth discontinuities), no more and no fewer.
  int coarse_mesh_stride = 4;
  PhongMaterial reconstruction_material{{{0.5f, 0.5f, 0.5f}, 0.f, 1.f}, "reconstruction", {0.f, 0.f, 0.f}};
  colormap::ToneMapOptions tone_map{};  ///< the operator of the composites (and the colour mappings)
  EnvironmentLight environment = EnvironmentLight::Directional;
  std::optional<BufferName<brdf::Materials>> materials_buffer;  ///< none: no Materials input
  /// ObjectPlacements of the objects (virtual_model.h), e.g. resolved on a real surface at the
  /// first frame; none: the placements in DirSceneContent.
  std::optional<BufferName<ObjectPlacements>> placements_buffer;
  /// The frame's real lights (e.g. lights::kLights, extracted from the probe every frame), put
  /// before DirSceneContent::lights; none: DirSceneContent's lights alone.
  std::optional<BufferName<lights::LightSet>> real_lights_buffer;
  /// Those real lights' directional ones within this many degrees of each other are merged into
  /// one (lights::merge_close_directional_lights: the power stays) before they light the scene;
  /// 0: every light as it comes.
  float merge_lights_degrees = 0.f;
  /// Per-pixel k_d of the camera's real surfaces, modulating the cluster k_d of diffuse real
  /// surfaces (camera_albedo.h); none: the clusters' k_d alone.
  std::optional<RealAlbedoBuffers> albedo_buffers;
  bool temporal_smoothing = true;
  TemporalOptions temporal{};
  /// Anti-aliased outlines (edge_coverage.h): edge_samples^2 sub-pixel rays per outline pixel
  /// give its fractional virtual coverage; 0: the centre sample's 0 or 1.
  int edge_samples = 4;
  CompositeRule composite = CompositeRule::Additive;  ///< composite.h
  /// The camera's look on the virtual layer (camera_look_stage.h): with any artefact on, a
  /// camera_look stage, and the composite reads it; none (or no artefact): the sharp render.
  std::optional<CameraLookOptions> camera_look;
  /// The frames whose plain composite ("composite") is computed; empty: every frame. The others
  /// get an empty image: where a colour-mapped composite is the final picture, the plain one is
  /// an intermediate that the report shows on a few frames, and its camera look (the motion blur
  /// over the whole differential layer) costs as much as the final one's on real input.
  std::function<bool(std::int64_t)> composite_frames;
};

/// What the stages add to every frame's real geometry.
struct DirSceneContent {
  std::vector<MrLight> lights;  ///< real lights that do not change, and virtual lights
  std::vector<std::pair<VirtualModel, Placement>> objects;
  /// Pre-modelled objects of the real scene (add_real_model: a real mirror or glass), in place of
  /// the reconstruction's triangles within kRealObjectMargin of them (real_object_carving.h).
  std::vector<std::pair<VirtualModel, Placement>> real_objects{};
};

class DirRenderStage;

/// The stages of add_dir_stages whose summaries the report shows.
struct DirStages {
  VplStage* vpls = nullptr;
  DirRenderStage* dir = nullptr;
  CameraLookStage* camera_look = nullptr;  ///< none without DirStageOptions::camera_look
  colormap::ToneMapStage* tone_map = nullptr;
};

/// Adds the six stages above (and camera_look with DirStageOptions::camera_look) for `backend` (core/stage_backend.h:
/// Backend::Cpu renders without a GPU, Backend::Vulkan needs `context`, which must outlive the graph).
DirStages add_dir_stages(FrameGraph& graph, Backend backend, vk::VulkanContext* context, DirSceneContent content,
                         const DirStageOptions& options = {});

/// Step 1 (scene): the mixed-reality scene of the frame.
class MrSceneStage final : public Stage {
 public:
  MrSceneStage(DirSceneContent content, const DirStageOptions& options);
  [[nodiscard]] std::string name() const override { return "mr_scene"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  DirSceneContent content_;
  DepthMeshOptions mesh_;
  int coarse_mesh_stride_;
  PhongMaterial reconstruction_material_;
  EnvironmentLight environment_;
  std::optional<BufferName<brdf::Materials>> materials_buffer_;
  std::optional<BufferName<ObjectPlacements>> placements_buffer_;
  std::optional<BufferName<lights::LightSet>> real_lights_buffer_;
  float merge_lights_degrees_;
  Read<FrameInfo> frame_;
  Read<PositionMap> positions_;
  Read<NormalMap> normals_;
  Read<brdf::Materials> materials_;
  Read<ObjectPlacements> placements_;
  Read<lights::LightSet> real_lights_;
  Write<MrScene> scene_;
};

/// Step 2 (primary lights and VPLs). With a Vulkan context (may be null), the cone searches of
/// BounceMethod::PointCone (bounces >= 2) and the RSMs of VplSource::ReflectiveShadowMaps
/// (rasterised, reflective_shadow_map_vk.h) run on the GPU.
class VplStage final : public Stage {
 public:
  explicit VplStage(VplOptions options, vk::VulkanContext* context = nullptr);
  ~VplStage() override;
  [[nodiscard]] std::string name() const override { return "vpls"; }
  /// Vulkan when a step of its options runs on the GPU (the rest, and its buffers, on the host).
  [[nodiscard]] Backend backend() const override {
    return cone_search_ || reflective_shadow_maps_ ? Backend::Vulkan : Backend::Cpu;
  }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

  /// What the frames' VPLs were: frames, the mean count per frame by bounce (index 0 = emitters,
  /// 1 = first bounce, ...), and the first frame's count of bounces >= 2 (zero for the
  /// multiple-bounce light source, which has nothing to continue yet).
  struct Summary {
    int frames = 0;
    std::vector<double> mean_by_bounce;
    int first_frame_later_bounces = 0;
  };
  [[nodiscard]] Summary summary() const;
  [[nodiscard]] const VplOptions& options() const { return options_; }

 private:
  /// The multiple-bounce light source (vpl.h) reads the previous frame's VPLs.
  [[nodiscard]] bool continues_previous_vpls() const {
    return options_.bounces > 1 && options_.bounce_method == BounceMethod::PreviousFrame;
  }
  /// The flux budget and the multiple-bounce light source read the previous frame's VPLs.
  [[nodiscard]] bool reads_previous_vpls() const {
    return options_.budget == VplBudget::ByPreviousFlux || continues_previous_vpls();
  }
  VplOptions options_;
  std::unique_ptr<ConeSearchVk> cone_search_;
  std::unique_ptr<ReflectiveShadowMapsVk> reflective_shadow_maps_;
  Read<MrScene> scene_;
  ReadPrevious<VplSet> previous_;
  Write<VplSet> vpls_;
  int frames_ = 0;
  std::vector<double> count_by_bounce_;  ///< summed over the frames
  int first_frame_later_bounces_ = 0;
};

/// Steps 3-4 (G-buffer, shadow maps, ISMs, one-pass shading of L_rv and L_r).
class DirRenderStage final : public Stage {
 public:
  /// `albedo_buffers`: DirStageOptions::albedo_buffers.
  /// `edge_samples`: DirStageOptions::edge_samples.
  DirRenderStage(vk::VulkanContext* context, DirRenderOptions options,
                 std::optional<RealAlbedoBuffers> albedo_buffers = std::nullopt, int edge_samples = 0);
  ~DirRenderStage() override;
  [[nodiscard]] std::string name() const override { return "dir"; }
  /// Vulkan with a context (rasterisation on the GPU, shading where DirBackend says); its
  /// buffers live on the host either way.
  [[nodiscard]] Backend backend() const override { return context_ ? Backend::Vulkan : Backend::Cpu; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  /// The steps of every frame rendered through DirRendererVk, in order (empty on the CPU
  /// backend): the device's G-buffer and shadow maps (timestamps), and the ISMs, shading and
  /// merge wherever they ran (report.json's dir_steps).
  [[nodiscard]] const std::vector<DirVkTimings>& step_timings() const { return step_timings_; }

 private:
  vk::VulkanContext* context_;
  DirRenderOptions options_;
  std::optional<RealAlbedoBuffers> albedo_buffers_;
  std::vector<DirVkTimings> step_timings_;
  int edge_samples_;
  std::unique_ptr<DirRendererVk> renderer_;
  std::pair<int, int> renderer_size_{0, 0};
  Read<FrameInfo> frame_;
  Read<ColorImage> color_;
  Read<PositionMap> positions_;
  Read<MrScene> scene_;
  Read<VplSet> vpls_;
  Read<RadianceImage> albedo_;
  Read<Mask> albedo_valid_;
  Write<DifferentialImages> images_;
  Write<GBuffer> gbuffer_;
  Write<SpecularBackProjection> back_projection_;
};

/// Step 6 (temporal smoothing of the indirect light).
class IndirectSmoothingStage final : public Stage {
 public:
  IndirectSmoothingStage(bool enabled, TemporalOptions options) : enabled_(enabled), options_(std::move(options)) {}
  [[nodiscard]] std::string name() const override { return "indirect_smoothing"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  bool enabled_;
  TemporalOptions options_;
  Read<DifferentialImages> images_;
  Read<GBuffer> gbuffer_;
  Read<FrameInfo> frame_;
  ReadPrevious<TemporalHistory> previous_history_;
  Write<TemporalHistory> history_;
  Write<RadianceImage> real_virtual_;
  Write<RadianceImage> real_;
  Write<RadianceImage> indirect_;
  Write<CoverageImage> coverage_;
};

/// Step 7 (tone mapping and differential composite).
class DifferentialCompositeStage final : public Stage {
 public:
  /// With `camera_look`, also reads colormap::CameraLook "camera_look" (camera_look_stage.h).
  /// `frames`: the frames it computes the composite for (empty: every frame); the others get an
  /// empty image.
  explicit DifferentialCompositeStage(bool camera_look = false, CompositeRule rule = CompositeRule::Additive,
                                      std::function<bool(std::int64_t)> frames = {})
      : camera_look_(camera_look), rule_(rule), frames_(std::move(frames)) {}
  [[nodiscard]] std::string name() const override { return "differential_composite"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  bool camera_look_;
  CompositeRule rule_;
  std::function<bool(std::int64_t)> frames_;
  Read<colormap::ToneMap> tone_map_;
  Read<ColorImage> color_;
  Read<RadianceImage> real_virtual_;
  Read<RadianceImage> real_;
  Read<CoverageImage> coverage_;
  Read<GBuffer> gbuffer_;
  Read<SpecularBackProjection> back_projection_;
  Read<colormap::CameraLook> look_;
  Write<ColorImage> composite_;
};

}  // namespace relight::render
