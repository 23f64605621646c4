#include "relight/render/dir/dir_stage.h"

#include <algorithm>
#include <cmath>

#include "relight/colormap/buffers.h"
#include "relight/colormap/tone_map_stage.h"
#include "relight/core/error.h"
#include "relight/lights/merge_lights.h"
#include "relight/render/dir/camera_albedo.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/edge_coverage.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/real_object_carving.h"
#include "relight/render/scene/scene_lights.h"

namespace relight::render {

namespace {

/// The clusters as MrScene materials (index = cluster), and the fallback for pixels without one.
void add_cluster_materials(MrScene& scene, const brdf::Materials& materials, DepthMeshMaterials& mesh_materials,
                           const PhongMaterial& fallback) {
  Eigen::Vector3f weighted = Eigen::Vector3f::Zero();
  float pixels = 0.f;
  mesh_materials.material_of_label.push_back(0);  // label 0: no cluster, replaced below
  for (std::size_t i = 0; i < materials.clusters.size(); ++i) {
    const brdf::MaterialParams& c = materials.clusters[i];
    mesh_materials.material_of_label.push_back(scene.add_material(
        {{c.kd, c.ks, std::max(c.n, 1.f)}, "cluster " + std::to_string(i), Eigen::Vector3f::Zero()}));
    weighted += static_cast<float>(c.pixels) * c.kd;
    pixels += static_cast<float>(c.pixels);
  }
  PhongMaterial unclustered = fallback;
  unclustered.name = "unclustered";
  if (pixels > 0.f) unclustered.kd = weighted / pixels;
  mesh_materials.material = scene.add_material(unclustered);
  mesh_materials.material_of_label[0] = mesh_materials.material;
  mesh_materials.labels = &materials.ids;
}

/// The frame's camera for images of the given size.
MrCamera frame_camera(const FrameInfo& frame, int width, int height) {
  MrCamera camera{frame.intrinsics, frame.camera_to_world.value_or(Pose::Identity())};
  camera.intrinsics.width = width;
  camera.intrinsics.height = height;
  return camera;
}

}  // namespace

DirStages add_dir_stages(FrameGraph& graph, Backend backend, vk::VulkanContext* given_context, DirSceneContent content,
                         const DirStageOptions& options) {
  vk::VulkanContext* context = context_for_backend(backend, given_context, "add_dir_stages");
  DirStages stages;
  graph.emplace<MrSceneStage>(std::move(content), options);
  stages.vpls = &graph.emplace<VplStage>(options.vpls, context);
  stages.dir = &graph.emplace<DirRenderStage>(context, options.renderer, options.albedo_buffers, options.edge_samples);
  graph.emplace<IndirectSmoothingStage>(options.temporal_smoothing, options.temporal);
  const bool camera_look = options.camera_look && options.camera_look->artefacts.any();
  if (camera_look) stages.camera_look = &graph.emplace<CameraLookStage>(*options.camera_look);
  stages.tone_map = &graph.emplace<colormap::ToneMapStage>(options.tone_map);
  graph.emplace<DifferentialCompositeStage>(camera_look, options.composite, options.composite_frames);
  return stages;
}

// ---- mr_scene ----------------------------------------------------------------------------------

MrSceneStage::MrSceneStage(DirSceneContent content, const DirStageOptions& options)
    : content_(std::move(content)),
      mesh_(options.mesh),
      coarse_mesh_stride_(options.coarse_mesh_stride),
      reconstruction_material_(options.reconstruction_material),
      environment_(options.environment),
      materials_buffer_(options.materials_buffer),
      placements_buffer_(options.placements_buffer),
      real_lights_buffer_(options.real_lights_buffer),
      merge_lights_degrees_(options.merge_lights_degrees) {}

void MrSceneStage::declare(StageBuilder& builder) {
  frame_ = builder.read(kFrame);
  positions_ = builder.read(kPositions);
  normals_ = builder.read(kNormals);
  if (materials_buffer_) materials_ = builder.read(*materials_buffer_);
  if (placements_buffer_) placements_ = builder.read(*placements_buffer_);
  if (real_lights_buffer_) real_lights_ = builder.read(*real_lights_buffer_);
  scene_ = builder.write(kMrScene);
}

void MrSceneStage::run(StageContext& context) {
  const PositionMap& positions = context.get(positions_);
  const brdf::Materials* cluster_materials = materials_buffer_ ? &context.get(materials_) : nullptr;
  MrScene& scene = context.get(scene_);
  scene = MrScene{};
  DepthMeshMaterials materials;
  if (cluster_materials && cluster_materials->ids.width() == positions.width() &&
      cluster_materials->ids.height() == positions.height())
    add_cluster_materials(scene, *cluster_materials, materials, reconstruction_material_);
  else
    materials.material = scene.add_material(reconstruction_material_);
  const Pose camera_to_world = context.get(frame_).camera_to_world.value_or(Pose::Identity());
  // The edge rule (depth_mesh.h) keeps every surface up to a slant of at least 75 degrees, where
  // an edge spans 1/cos(75 deg) ~ 4 pixel footprints: on a 640-pixel-wide image its
  // relative_edge allows more, on a coarse one a grid step spans more of a surface and the rule
  // grows with it (at 160 x 120 the table top behind glass was dropped and the refracted rays
  // fell to the floor).
  const double focal = context.get(frame_).intrinsics.fx;
  const auto slant_limited = [focal](DepthMeshOptions options) {
    if (focal > 0.0)
      options.relative_edge = std::max(options.relative_edge, static_cast<float>(4.0 * options.stride / focal));
    return options;
  };
  const DepthMeshOptions fine = slant_limited(mesh_);
  TriangleMesh mesh = mesh_from_positions(positions, &context.get(normals_), camera_to_world, materials, fine);
  mesh.name = "reconstruction";
  scene.meshes.push_back(std::move(mesh));
  if (real_lights_buffer_)
    add_lights(scene, lights::merge_close_directional_lights(context.get(real_lights_), merge_lights_degrees_));
  scene.lights.insert(scene.lights.end(), content_.lights.begin(), content_.lights.end());
  if (environment_ == EnvironmentLight::Vpls)
    for (MrLight& light : scene.lights) light.through_vpl = light.kind == LightKind::Directional;
  // The reconstruction's coarse copy for the shadow maps and the VPLs (dir_stage.h).
  const auto coarse_stride =
      static_cast<int>(std::lround(coarse_mesh_stride_ * static_cast<double>(positions.width()) / 640.0));
  if (coarse_stride > mesh_.stride) {
    // The edge rule scaled with the grid step, so that the stand-in drops the same slopes (depth
    // discontinuities) as the rendered mesh, no more and no fewer.
    const float scale = static_cast<float>(coarse_stride) / static_cast<float>(std::max(mesh_.stride, 1));
    DepthMeshOptions coarse = mesh_;
    coarse.stride = coarse_stride;
    coarse.relative_edge *= scale;
    coarse.min_edge *= scale;
    coarse = slant_limited(coarse);
    scene.coarse_real_meshes.push_back(
        mesh_from_positions(positions, &context.get(normals_), camera_to_world, materials, coarse));
    scene.coarse_real_meshes.back().name = "reconstruction (coarse)";
  }
  const std::size_t reconstruction = scene.meshes.size() - 1;
  for (const auto& [model, placement] : content_.real_objects) {
    const std::span<const TriangleMesh> object = add_real_model(scene, model, placement);
    remove_triangles_within(scene.meshes[reconstruction], object, kRealObjectMargin);
    if (scene.coarse_real_meshes.empty()) continue;
    remove_triangles_within(scene.coarse_real_meshes.front(), object, kRealObjectMargin);  // the reconstruction's
    scene.coarse_real_meshes.insert(scene.coarse_real_meshes.end(), object.begin(), object.end());
  }
  if (!placements_buffer_) {
    for (const auto& [model, placement] : content_.objects) add_virtual_model(scene, model, placement);
    return;
  }
  const ObjectPlacements& placements = context.get(placements_);
  if (!placements.resolved) return;
  if (placements.placements.size() != content_.objects.size())
    throw LogicError("mr_scene: " + std::to_string(placements.placements.size()) + " placements for " +
                     std::to_string(content_.objects.size()) + " objects");
  for (std::size_t i = 0; i < content_.objects.size(); ++i)
    add_virtual_model(scene, content_.objects[i].first, placements.placements[i]);
}

// ---- vpls --------------------------------------------------------------------------------------

VplStage::VplStage(VplOptions options, vk::VulkanContext* context) : options_(std::move(options)) {
  if (context && options_.bounces > 1 && options_.bounce_method == BounceMethod::PointCone)
    cone_search_ = std::make_unique<ConeSearchVk>(*context);
  if (context && options_.source == VplSource::ReflectiveShadowMaps)
    reflective_shadow_maps_ = std::make_unique<ReflectiveShadowMapsVk>(*context);
}

VplStage::~VplStage() = default;

void VplStage::declare(StageBuilder& builder) {
  scene_ = builder.read(kMrScene);
  if (reads_previous_vpls()) previous_ = builder.read_previous(kVpls);
  vpls_ = builder.write(kVpls);
}

void VplStage::run(StageContext& context) {
  const MrScene& scene = context.get(scene_);
  const VplSet* previous = reads_previous_vpls() ? context.get(previous_) : nullptr;
  if (options_.budget == VplBudget::ByPreviousFlux)
    options_.previous_flux = previous ? vpl_flux_per_light(previous->vpls, scene.lights.size()) : std::vector<double>{};
  if (continues_previous_vpls()) {
    options_.previous_vpls = previous ? std::span<const Vpl>(previous->vpls) : std::span<const Vpl>{};
    options_.previous_surfaces = previous ? std::span<const Phong>(previous->surfaces) : std::span<const Phong>{};
  }
  if (reflective_shadow_maps_) reflective_shadow_maps_->set_scene(scene);
  // Onto the coarse copy of the reconstruction when there is one: its BVH builds in a quarter of
  // the time, and a VPL lands on the same surface within a few millimetres.
  const RayTracer tracer(scene.coarse_real_meshes.empty() ? scene : coarse_scene(scene), RayTracer::Build::Fast);
  VplSet& out = context.get(vpls_);
  out.vpls =
      generate_vpls(scene, tracer, options_,
                    {.cone_search = cone_search_.get(), .reflective_shadow_maps = reflective_shadow_maps_.get()});
  // Only the multiple-bounce light source reads them, next frame.
  if (continues_previous_vpls()) out.surfaces = vpl_surfaces(scene, out.vpls);
  for (const Vpl& vpl : out.vpls) {
    const auto bounce = static_cast<std::size_t>(std::max(vpl.bounce, 0));
    if (count_by_bounce_.size() <= bounce) count_by_bounce_.resize(bounce + 1, 0.0);
    count_by_bounce_[bounce] += 1.0;
    if (frames_ == 0 && vpl.bounce >= 2) ++first_frame_later_bounces_;
  }
  ++frames_;
  options_.previous_vpls = {};  // they belong to the history buffer, which the graph may reuse
  options_.previous_surfaces = {};
  // The GPU time of this frame's searches and RSM passes (the helpers count since the last take).
  const double gpu_ms = (cone_search_ ? cone_search_->take_gpu_ms() : 0.0) +
                        (reflective_shadow_maps_ ? reflective_shadow_maps_->take_gpu_ms() : 0.0);
  if (gpu_ms > 0.0) context.report_device_ms(gpu_ms);
}

VplStage::Summary VplStage::summary() const {
  Summary summary{frames_, count_by_bounce_, first_frame_later_bounces_};
  for (double& count : summary.mean_by_bounce) count /= std::max(frames_, 1);
  return summary;
}

// ---- dir ---------------------------------------------------------------------------------------

DirRenderStage::DirRenderStage(vk::VulkanContext* context, DirRenderOptions options,
                               std::optional<RealAlbedoBuffers> albedo_buffers, int edge_samples)
    : context_(context), options_(options), albedo_buffers_(albedo_buffers), edge_samples_(edge_samples) {}

DirRenderStage::~DirRenderStage() = default;

void DirRenderStage::declare(StageBuilder& builder) {
  frame_ = builder.read(kFrame);
  color_ = builder.read(kColor);
  positions_ = builder.read(kPositions);
  scene_ = builder.read(kMrScene);
  vpls_ = builder.read(kVpls);
  if (albedo_buffers_) {
    albedo_ = builder.read(albedo_buffers_->albedo);
    albedo_valid_ = builder.read(albedo_buffers_->valid);
  }
  images_ = builder.write(kDirImages);
  gbuffer_ = builder.write(kDirGBuffer);
  back_projection_ = builder.write(kSpecularBackProjection);
}

void DirRenderStage::run(StageContext& context) {
  const ColorImage& color = context.get(color_);
  const int width = color.width(), height = color.height();
  const PositionMap& positions = context.get(positions_);
  if (positions.width() != width || positions.height() != height)
    throw Error("dir: the colour image (" + std::to_string(width) + "x" + std::to_string(height) +
                ") and the position map (" + std::to_string(positions.width()) + "x" +
                std::to_string(positions.height()) + ") differ in size");
  const MrCamera camera = frame_camera(context.get(frame_), width, height);
  const MrScene& scene = context.get(scene_);
  const std::vector<Vpl>& vpls = context.get(vpls_).vpls;
  DifferentialImages& images = context.get(images_);
  GBuffer& gbuffer = context.get(gbuffer_);
  SpecularBackProjection& back_projection = context.get(back_projection_);
  if (!context_) {
    images = render_dir_cpu(scene, camera, vpls, options_, &gbuffer, &back_projection);
  } else {
    if (!renderer_ || renderer_size_ != std::pair{width, height}) {
      renderer_ = std::make_unique<DirRendererVk>(*context_, width, height);
      renderer_size_ = {width, height};
    }
    renderer_->set_scene(scene, options_);
    images = renderer_->render(camera, vpls, options_);
    gbuffer = renderer_->last_gbuffer();
    back_projection = renderer_->last_back_projection();
    // The GPU time of the steps that ran on the device (timestamps; none on devices without them).
    const DirVkTimings& t = renderer_->last_timings();
    step_timings_.push_back(t);
    const double gpu_ms =
        t.gbuffer_ms + t.shadow_maps_ms + (t.cpu_shading ? 0.0 : t.ism_ms + t.shading_ms + t.merge_ms);
    if (gpu_ms > 0.0) context.report_device_ms(gpu_ms);
  }
  if (edge_samples_ > 0 && scene.triangle_count(false) > 0) {
    const RayTracer virtual_tracer(virtual_part(scene), RayTracer::Build::Fast);
    (void)refine_edge_coverage(images.virtual_coverage, gbuffer, positions, virtual_tracer, camera,
                               {.samples = edge_samples_});
  }
  if (albedo_buffers_) {
    modulate_camera_albedo(images, gbuffer, scene, context.get(albedo_), context.get(albedo_valid_));
  }
}

// ---- indirect_smoothing ------------------------------------------------------------------------

void IndirectSmoothingStage::declare(StageBuilder& builder) {
  images_ = builder.read(kDirImages);
  gbuffer_ = builder.read(kDirGBuffer);
  frame_ = builder.read(kFrame);
  if (enabled_) {
    previous_history_ = builder.read_previous(kIndirectHistory);
    history_ = builder.write(kIndirectHistory);
  }
  real_virtual_ = builder.write(kRealVirtualRadiance);
  real_ = builder.write(kRealRadiance);
  indirect_ = builder.write(kRealVirtualIndirect);
  coverage_ = builder.write(kVirtualCoverage);
}

void IndirectSmoothingStage::run(StageContext& context) {
  DifferentialImages images = context.get(images_);
  if (enabled_) {
    const MrCamera camera = frame_camera(context.get(frame_), images.real_virtual.width(), images.real_virtual.height());
    context.get(history_) =
        smooth_indirect(images, context.get(gbuffer_), camera, context.get(previous_history_), options_);
  }
  context.get(real_virtual_) = std::move(images.real_virtual);
  context.get(real_) = std::move(images.real);
  context.get(indirect_) = std::move(images.indirect_real_virtual);
  context.get(coverage_) = std::move(images.virtual_coverage);
}

// ---- differential_composite --------------------------------------------------------------------

void DifferentialCompositeStage::declare(StageBuilder& builder) {
  color_ = builder.read(kColor);
  real_virtual_ = builder.read(kRealVirtualRadiance);
  real_ = builder.read(kRealRadiance);
  coverage_ = builder.read(kVirtualCoverage);
  gbuffer_ = builder.read(kDirGBuffer);
  back_projection_ = builder.read(kSpecularBackProjection);
  tone_map_ = builder.read(colormap::kToneMap);
  if (camera_look_) look_ = builder.read(colormap::kCameraLook);
  composite_ = builder.write(kComposite);
}

void DifferentialCompositeStage::run(StageContext& context) {
  if (frames_ && !frames_(context.frame_index())) {
    context.get(composite_) = ColorImage{};
    return;
  }
  const ColorImage& color = context.get(color_);
  const RadianceImage& real_virtual = context.get(real_virtual_);
  if (color.width() != real_virtual.width() || color.height() != real_virtual.height())
    throw Error("differential_composite: the colour image (" + std::to_string(color.width()) + "x" +
                std::to_string(color.height()) + ") and the rendered image (" + std::to_string(real_virtual.width()) +
                "x" + std::to_string(real_virtual.height()) + ") differ in size");
  context.get(composite_) =
      differential_composite(color, real_virtual, context.get(real_), context.get(coverage_), context.get(tone_map_),
                             {rule_, camera_look_ ? &context.get(look_) : nullptr,
                              &context.get(gbuffer_).virtual_surface, &context.get(back_projection_)});
}

}  // namespace relight::render
