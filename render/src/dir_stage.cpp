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
  composite_ = builder.write<ColorImage>("composite");
  real_virtual_ = builder.write<RadianceImage>("L_rv");
  real_ = builder.write<RadianceImage>("L_r");
  coverage_ = builder.write<CoverageImage>("virtual_coverage");
}

void DirStage::build_scene(const PositionMap& positions, const NormalMap& normals, const Pose& camera_to_world) {
  scene_ = MrScene{};
  DepthMeshMaterials materials;
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
  build_scene(positions, context.get(normals_), camera_to_world);

  const std::vector<Vpl> vpls = generate_vpls(scene_, RayTracer(scene_), options_.vpls);
  vpl_count_ = vpls.size();
  MrCamera camera{frame.intrinsics, camera_to_world};
  camera.intrinsics.width = width;
  camera.intrinsics.height = height;
  DifferentialImages images;
  if (context_) {
    if (!renderer_ || renderer_size_ != std::pair{width, height}) {
      renderer_ = std::make_unique<DirRendererVk>(*context_, width, height);
      renderer_size_ = {width, height};
    }
    renderer_->set_scene(scene_, options_.renderer);
    images = renderer_->render(camera, vpls, options_.renderer);
  } else {
    images = render_dir_cpu(scene_, camera, vpls, options_.renderer);
  }
  context.get(composite_) =
      differential_composite(color, images.real_virtual, images.real, images.virtual_coverage, options_.tone_map);
  context.get(real_virtual_) = std::move(images.real_virtual);
  context.get(real_) = std::move(images.real);
  context.get(coverage_) = std::move(images.virtual_coverage);
}

}  // namespace relight::render
