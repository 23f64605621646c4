// Rasterised reflective shadow maps (reflective_shadow_map_vk.h): G-buffer passes from the light.
#include "relight/render/vpl/reflective_shadow_map_vk.h"

#include <array>
#include <optional>
#include <utility>

#include "relight/core/error.h"
#include "relight/render/dir/gbuffer_vk.h"
#include "relight/vk/context.h"

namespace relight::render {
namespace {

// Which layers a G-buffer pass draws: both (a virtual light's RSM), or one.
enum Pass : std::size_t { kBothLayers, kRealLayer, kVirtualLayer, kPassCount };

std::optional<Layer> layer_of(Pass pass) {
  if (pass == kRealLayer) return Layer::Real;
  if (pass == kVirtualLayer) return Layer::Virtual;
  return std::nullopt;
}

/// The pinhole camera at the light whose pixel (x, y) looks through the RSM texel (x, y): camera
/// x, y, z along the view's tangent, bitangent and axis, focal length one texel per texel_side.
MrCamera light_camera(const MrLight& light, const RsmView& view) {
  MrCamera camera;
  const double focal = 1.0 / static_cast<double>(view.texel_side);
  const double centre = 0.5 * static_cast<double>(view.size) - 0.5;
  camera.intrinsics = PinholeIntrinsics{focal, focal, centre, centre, view.size, view.size};
  camera.camera_to_world.linear().col(0) = view.tangent.cast<double>();
  camera.camera_to_world.linear().col(1) = view.bitangent.cast<double>();
  camera.camera_to_world.linear().col(2) = view.axis.cast<double>();
  camera.camera_to_world.translation() = light.position.cast<double>();
  return camera;
}

/// The surface a G-buffer pixel holds, as the ray caster would report it.
std::optional<SurfaceHit> hit_at(const GBuffer& g, std::size_t i) {
  const std::uint16_t label = g.material.pixels()[i];
  if (label == 0) return std::nullopt;
  SurfaceHit hit;
  hit.t = g.distance.pixels()[i];
  const Float3& p = g.position.pixels()[i];
  const Float3& n = g.normal.pixels()[i];
  hit.point = {p.x, p.y, p.z};
  hit.geometric_normal = hit.interpolated_normal = hit.shading_normal = Eigen::Vector3f(n.x, n.y, n.z);
  hit.material = static_cast<std::uint32_t>(label - 1);
  hit.real = g.virtual_surface.pixels()[i] == 0;
  return hit;
}

}  // namespace

struct ReflectiveShadowMapsVk::Impl {
  explicit Impl(vk::VulkanContext& context) : context(context) {}
  vk::VulkanContext& context;
  int size = 0;
  double untaken_ms = 0.0;  // every pass's GPU time since the last take_gpu_ms()
  std::array<std::unique_ptr<GBufferVk>, kPassCount> passes;
  std::array<bool, kPassCount> uploaded{};
  double gpu_ms = 0.0;

  /// The pass's G-buffer at `size`, created (and given the scene) on first use.
  GBufferVk& pass(Pass which, const MrScene& scene) {
    auto& g = passes[which];
    if (!g) g = std::make_unique<GBufferVk>(context, size, size);
    if (!uploaded[which]) {
      g->set_scene(scene, layer_of(which));
      uploaded[which] = true;
    }
    return *g;
  }
  GBuffer draw(Pass which, const MrScene& scene, const MrCamera& camera) {
    GBufferVk& g = pass(which, scene);
    GBuffer out = g.render(camera);
    gpu_ms += g.last_gpu_ms();
    untaken_ms += g.last_gpu_ms();
    return out;
  }
};

ReflectiveShadowMapsVk::ReflectiveShadowMapsVk(vk::VulkanContext& context) : impl_(std::make_unique<Impl>(context)) {
  if (context.graphics_queue_family() != context.compute_queue_family())
    throw Error("Vulkan device '" + context.device_info().name + "' has no queue for both graphics and compute");
}

ReflectiveShadowMapsVk::~ReflectiveShadowMapsVk() = default;

double ReflectiveShadowMapsVk::last_gpu_ms() const { return impl_->gpu_ms; }

double ReflectiveShadowMapsVk::take_gpu_ms() { return std::exchange(impl_->untaken_ms, 0.0); }

void ReflectiveShadowMapsVk::set_scene(const MrScene& scene) {
  impl_->uploaded.fill(false);
  for (std::size_t p = 0; p < kPassCount; ++p) {
    if (impl_->passes[p]) (void)impl_->pass(static_cast<Pass>(p), scene);
  }
}

std::vector<ReflectiveShadowMap> ReflectiveShadowMapsVk::render(const MrScene& scene, std::size_t light_index, int size) {
  const RsmView view = rsm_view(scene, light_index, size, "ReflectiveShadowMapsVk");
  Impl& r = *impl_;
  if (size != r.size) {  // new targets; each takes the scene again on first use
    r.size = size;
    r.passes = {};
    r.uploaded.fill(false);
  }
  r.gpu_ms = 0.0;
  const MrLight& light = scene.lights[light_index];
  const MrCamera camera = light_camera(light, view);
  const GBuffer first = r.draw(light.real ? kRealLayer : kBothLayers, scene, camera);
  const std::optional<GBuffer> virtual_layer =
      light.real ? std::optional<GBuffer>(r.draw(kVirtualLayer, scene, camera)) : std::nullopt;
  return assemble_reflective_shadow_maps(scene, light_index, view, [&](int x, int y, const Eigen::Vector3f&) {
    const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x);
    RsmTexelHits seen{hit_at(first, i), std::nullopt};
    if (!virtual_layer) return seen;
    seen.virtual_in_front = hit_at(*virtual_layer, i);
    const bool behind = seen.virtual_in_front && seen.first && !(seen.virtual_in_front->t < seen.first->t);
    if (behind) seen.virtual_in_front.reset();
    return seen;
  });
}

}  // namespace relight::render
