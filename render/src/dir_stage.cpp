#include "relight/render/dir_stage.h"

#include "relight/core/error.h"
#include "relight/render/composite.h"
#include "relight/render/ray_tracer.h"

namespace relight::render {

DirStage::DirStage(vk::VulkanContext* context, DirSceneContent content, DirStageOptions options)
    : context_(context), content_(std::move(content)), options_(std::move(options)) {}

DirStage::~DirStage() = default;

void DirStage::declare(StageBuilder& builder) {
  frame_ = builder.read<FrameInfo>("frame");
  color_ = builder.read<ColorImage>("color");
  positions_ = builder.read<PositionMap>("positions");
  normals_ = builder.read<NormalMap>("normals");
  if (!options_.materials_buffer.empty()) materials_ = builder.read<brdf::Materials>(options_.materials_buffer);
  composite_ = builder.write<ColorImage>("composite");
  real_virtual_ = builder.write<RadianceImage>("L_rv");
  real_ = builder.write<RadianceImage>("L_r");
  coverage_ = builder.write<CoverageImage>("virtual_coverage");
  indirect_ = builder.write<RadianceImage>("L_rv_indirect");
}

namespace {

/// The clusters as MrScene materials (index = cluster), and the fallback for pixels without one.
void add_cluster_materials(MrScene& scene, const brdf::Materials& materials, DepthMeshMaterials& mesh_materials,
                           const PhongMaterial& fallback) {
  Eigen::Vector3f weighted = Eigen::Vector3f::Zero();
  float pixels = 0.f;
  mesh_materials.material_of_label.push_back(0);  // label 0: no cluster, replaced below
  for (std::size_t i = 0; i < materials.clusters.size(); ++i) {
    const brdf::MaterialParams& c = materials.clusters[i];
    mesh_materials.material_of_label.push_back(
        scene.add_material({"cluster " + std::to_string(i), c.kd, c.ks, std::max(c.n, 1.f), Eigen::Vector3f::Zero()}));
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

}  // namespace

void DirStage::build_scene(const PositionMap& positions, const NormalMap& normals, const Pose& camera_to_world,
                           const brdf::Materials* cluster_materials) {
  scene_ = MrScene{};
  DepthMeshMaterials materials;
  if (cluster_materials && cluster_materials->ids.width() == positions.width() &&
      cluster_materials->ids.height() == positions.height())
    add_cluster_materials(scene_, *cluster_materials, materials, options_.reconstruction_material);
  else
    materials.material = scene_.add_material(options_.reconstruction_material);
  TriangleMesh mesh = mesh_from_positions(positions, &normals, camera_to_world, materials, options_.mesh);
  mesh.name = "reconstruction";
  scene_.meshes.push_back(std::move(mesh));
  scene_.lights = content_.lights;
  for (const auto& [model, placement] : content_.objects) add_virtual_model(scene_, model, placement);
}

void DirStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  const ColorImage& color = context.get(color_);
  const PositionMap& positions = context.get(positions_);
  const int width = positions.width(), height = positions.height();
  if (color.width() != width || color.height() != height)
    throw Error("dir: the colour image (" + std::to_string(color.width()) + "x" + std::to_string(color.height()) +
                ") and the position map (" + std::to_string(width) + "x" + std::to_string(height) + ") differ in size");
  const Pose camera_to_world = frame.camera_to_world.value_or(Pose::Identity());
  build_scene(positions, context.get(normals_), camera_to_world,
              options_.materials_buffer.empty() ? nullptr : &context.get(materials_));

  const std::vector<Vpl> vpls = generate_vpls(scene_, RayTracer(scene_, RayTracer::Build::Fast), options_.vpls);
  vpl_count_ = vpls.size();
  if (options_.vpls.budget == VplBudget::ByPreviousFlux)
    options_.vpls.previous_flux = vpl_flux_per_light(vpls, scene_.lights.size());
  MrCamera camera{frame.intrinsics, camera_to_world};
  camera.intrinsics.width = width;
  camera.intrinsics.height = height;
  DifferentialImages images;
  GBuffer cpu_gbuffer;
  if (context_) {
    if (!renderer_ || renderer_size_ != std::pair{width, height}) {
      renderer_ = std::make_unique<DirRendererVk>(*context_, width, height);
      renderer_size_ = {width, height};
    }
    renderer_->set_scene(scene_, options_.renderer);
    images = renderer_->render(camera, vpls, options_.renderer);
  } else {
    images = render_dir_cpu(scene_, camera, vpls, options_.renderer, &cpu_gbuffer);
  }
  if (options_.temporal_smoothing)
    history_ = smooth_indirect(images, context_ ? renderer_->last_gbuffer() : cpu_gbuffer, camera,
                               history_ ? &*history_ : nullptr, options_.temporal);
  context.get(composite_) =
      differential_composite(color, images.real_virtual, images.real, images.virtual_coverage, options_.tone_map);
  context.get(real_virtual_) = std::move(images.real_virtual);
  context.get(real_) = std::move(images.real);
  context.get(coverage_) = std::move(images.virtual_coverage);
  context.get(indirect_) = std::move(images.indirect_real_virtual);
}

}  // namespace relight::render
