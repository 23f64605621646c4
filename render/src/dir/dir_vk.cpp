#include "relight/render/dir/dir_vk.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <future>
#include <map>
#include <optional>

#include "dir/ism_vk.h"
#include "dir/shadow_maps_vk.h"
#include "relight/core/error.h"
#include "relight/render/dir/gbuffer_vk.h"
#include "relight/render/dir/specular_shading.h"
#include "relight/shaders/dir_merge_comp.h"
#include "relight/shaders/dir_shade_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::render {
namespace detail {

struct ShadeParams {
  std::uint32_t width, height, light_count, vpl_count;
  std::int32_t shadow_tile, shadow_columns, shadow_rows, ism_tile;
  float min_distance;
  std::uint32_t flags, interleave, emitter_count;
  float camera_centre[4];
  float environment[4];  ///< w: DirOptions::real_depth_noise_sigmas
  float virtual_bounds[4];
  float scene_bounds[4];
};
static_assert(sizeof(ShadeParams) <= 128);

struct MergeParams {
  std::uint32_t width, height, interleave;
};

}  // namespace detail

namespace {

using detail::MergeParams;
using detail::ShadeParams;

float bits(std::uint32_t value) { return std::bit_cast<float>(value); }

constexpr std::uint32_t kNoTexture = 0xffffffffu;
/// A packed texture's header before its levels' (dir_texture.glsl).
constexpr std::uint32_t kTextureHeaderWords = 12;
/// A material's base-colour, emission, metallic-roughness and normal textures (material_textures).
constexpr std::size_t kTexturesPerMaterial = 4;

/// The scenes' textures as dir_texture.glsl reads them, and the header words of each material's
/// textures (kTexturesPerMaterial per material; kNoTexture: none). A texture shared by
/// several materials (or slots) is packed once.
struct PackedTextures {
  std::vector<std::uint32_t> words;
  std::vector<std::uint32_t> material_headers;
};

/// Per material its base-colour, emission, metallic-roughness and normal textures (null: none): when a new scene's list
/// equals the last one's, the packed textures on the device still hold (scenes are rebuilt every
/// frame, textures are shared). Held, not just compared: a texture freed and another made at its
/// address would look unchanged.
std::vector<std::shared_ptr<const Texture>> material_textures(const MrScene& scene) {
  std::vector<std::shared_ptr<const Texture>> out;
  for (const PhongMaterial& m : scene.materials) {
    out.push_back(m.base_color);
    out.push_back(m.emission_texture);
    out.push_back(m.metallic_roughness_texture);
    out.push_back(m.normal_texture);
  }
  return out;
}

PackedTextures pack_textures(const std::vector<std::shared_ptr<const Texture>>& textures) {
  PackedTextures out;
  std::map<const Texture*, std::uint32_t> headers;
  for (const std::shared_ptr<const Texture>& slot : textures) {
    const Texture* texture = slot.get();
    if (!texture) {
      out.material_headers.push_back(kNoTexture);
      continue;
    }
    if (const auto found = headers.find(texture); found != headers.end()) {
      out.material_headers.push_back(found->second);
      continue;
    }
    const auto header = static_cast<std::uint32_t>(out.words.size());
    const auto levels = static_cast<std::uint32_t>(texture->levels());
    const UvTransform& uv = texture->transform();
    const auto word = [](float value) { return std::bit_cast<std::uint32_t>(value); };
    out.words.insert(
        out.words.end(),
        {levels, static_cast<std::uint32_t>(texture->wrap_u()), static_cast<std::uint32_t>(texture->wrap_v()),
         static_cast<std::uint32_t>(std::max(texture->width(), texture->height())), word(uv.linear(0, 0)),
         word(uv.linear(0, 1)), word(uv.linear(1, 0)), word(uv.linear(1, 1)), word(uv.offset.x()), word(uv.offset.y()),
         word(uv.stretch()), 0u});
    const std::uint32_t first_texel = header + kTextureHeaderWords + 4 * levels;
    for (int l = 0; l < texture->levels(); ++l)
      out.words.insert(out.words.end(), {first_texel + static_cast<std::uint32_t>(texture->level_offset(l)),
                                         static_cast<std::uint32_t>(texture->level_width(l)),
                                         static_cast<std::uint32_t>(texture->level_height(l)),
                                         static_cast<std::uint32_t>(texture->encoding())});
    out.words.insert(out.words.end(), texture->texels().begin(), texture->texels().end());
    headers.emplace(texture, header);
    out.material_headers.push_back(header);
  }
  return out;
}

std::vector<float> pack_materials(const MrScene& scene, const std::vector<std::uint32_t>& texture_headers) {
  std::vector<float> out;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const PhongMaterial& m = scene.materials[i];
    const MetallicRoughness& pbr = m.metallic_roughness;
    out.insert(out.end(), {m.kd.x(),
                           m.kd.y(),
                           m.kd.z(),
                           m.ks,
                           m.emission.x(),
                           m.emission.y(),
                           m.emission.z(),
                           m.n,
                           bits(texture_headers[kTexturesPerMaterial * i]),
                           bits(texture_headers[kTexturesPerMaterial * i + 1]),
                           bits(texture_headers[kTexturesPerMaterial * i + 2]),
                           pbr.roughness,
                           pbr.base_color.x(),
                           pbr.base_color.y(),
                           pbr.base_color.z(),
                           pbr.metallic,
                           bits(texture_headers[kTexturesPerMaterial * i + 3]),
                           m.normal_scale,
                           0.f,
                           0.f});
  }
  return out;
}

std::vector<float> pack_lights(const MrScene& scene, const ShadowLayout& layout) {
  std::vector<float> out;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const MrLight& l = scene.lights[i];
    const Eigen::Vector3f d = l.direction.normalized();
    const auto kind = static_cast<std::uint32_t>(l.through_vpl                ? 3
                                                 : l.kind == LightKind::Point ? 0
                                                 : l.kind == LightKind::Spot  ? 1
                                                                              : 2);
    out.insert(out.end(), {l.position.x(), l.position.y(), l.position.z(), bits(kind), d.x(), d.y(), d.z(),
                           l.real ? 1.f : 0.f, l.intensity.x(), l.intensity.y(), l.intensity.z(), l.cos_inner,
                           l.cos_outer, bits(layout.light_views[i][0]), bits(layout.light_views[i][1]), 0.f});
  }
  return out;
}

/// The real layer's views, padded to rows x columns, then the virtual layer's: the shader finds
/// view i of layer l at i + l x rows x columns (dir_shade.comp, shadow_visibility).
std::vector<float> pack_views(const ShadowLayout& layout) {
  std::vector<float> out;
  const std::size_t slots = static_cast<std::size_t>(std::max(layout.rows(), 1) * layout.columns);
  for (int layer = 0; layer < 2; ++layer) {
    for (std::size_t i = 0; i < slots; ++i) {
      const ShadowView v = i < layout.views.size() ? layout.view(i, layer) : ShadowView{Eigen::Matrix4f::Zero(), {}, 0.f};
      out.insert(out.end(), v.world_to_clip.data(), v.world_to_clip.data() + 16);
      out.insert(out.end(), {v.eye.x(), v.eye.y(), v.eye.z(), v.eye.w(), v.texel_size, 0.f, 0.f, 0.f});
    }
  }
  return out;
}

std::vector<float> pack_vpls(std::span<const Vpl> vpls) {
  std::vector<float> out;
  out.reserve(vpls.size() * 20);
  for (const Vpl& v : vpls) {
    const std::uint32_t flags =
        (v.on_real_surface ? 1u : 0u) | (v.in_real_virtual ? 2u : 0u) | (v.in_real ? 4u : 0u) | (v.emitter() ? 8u : 0u);
    out.insert(out.end(), {v.position.x(),   v.position.y(),   v.position.z(),   bits(v.material),
                           v.normal.x(),     v.normal.y(),     v.normal.z(),     bits(flags),
                           v.incident.x(),   v.incident.y(),   v.incident.z(),   v.metallic_roughness.y(),
                           v.flux.x(),       v.flux.y(),       v.flux.z(),       v.metallic_roughness.z(),
                           v.kd_texture.x(), v.kd_texture.y(), v.kd_texture.z(), 0.f});
  }
  return out;
}

std::uint32_t shade_flags(const DirRenderOptions& options) {
  const bool rv = options.output != DirOutput::RealOnly, r = options.output != DirOutput::RealVirtualOnly;
  return (options.shading.direct ? 1u : 0u) | (options.shading.indirect ? 2u : 0u) | (rv ? 4u : 0u) | (r ? 8u : 0u);
}

}  // namespace

struct DirRendererVk::Impl {
  Impl(vk::VulkanContext& context, int width, int height)
      : context(context),
        width(width),
        height(height),
        gbuffer(context, width, height),
        shadow_maps(context),
        ism(context),
        shade(context, {.spirv = shaders::dir_shade_comp,
                        .storage_buffers = 9,
                        .push_constant_bytes = sizeof(ShadeParams),
                        .max_descriptor_sets = 2}),
        merge(context, {.spirv = shaders::dir_merge_comp,
                        .storage_buffers = 3,
                        .push_constant_bytes = sizeof(MergeParams),
                        .max_descriptor_sets = 2}),
        gbuffer_buffer(context, GBufferVk::packed_bytes(width, height)),
        shaded(context, 16 * sizeof(float) * static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        output(context, 16 * sizeof(float) * static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        merge_set(merge.bind({&gbuffer_buffer, &shaded, &output})),
        timers{vk::GpuTimer(context), vk::GpuTimer(context), vk::GpuTimer(context),
               vk::GpuTimer(context), vk::GpuTimer(context), vk::GpuTimer(context)} {}

  /// `slot` holds at least `data` (grown with headroom, never shrunk) with `data` uploaded. The
  /// headroom: the VPLs and lights of a frame vary in number (rays that miss), and a steady run
  /// should not allocate device memory every time a frame has one more.
  template <class T>
  void upload(std::optional<vk::VulkanBuffer>& slot, const std::vector<T>& data) {
    static_assert(sizeof(T) == sizeof(float));
    vk::reserve_with_headroom(slot, context, std::max<std::size_t>(data.size(), 4) * sizeof(float));
    if (!data.empty()) context.transfer().upload(std::as_bytes(std::span(data)), *slot);
  }

  vk::VulkanContext& context;
  int width, height;
  GBufferVk gbuffer;
  detail::ShadowMapsVk shadow_maps;
  detail::IsmVk ism;
  vk::ComputePipeline shade, merge;
  vk::VulkanBuffer gbuffer_buffer, shaded, output;
  vk::UniqueDescriptorSet merge_set;
  std::optional<vk::VulkanBuffer> materials, lights, views, vpls, textures;
  std::vector<std::shared_ptr<const Texture>> uploaded_textures;  // per material, of the packed `textures`
  std::vector<std::uint32_t> texture_headers;                     // kTexturesPerMaterial per material
  vk::UniqueDescriptorSet shade_set;
  std::array<vk::GpuTimer, 6> timers;
  std::optional<MrScene> scene;  ///< the last set_scene's materials, lights and environment (no meshes)
  std::unique_ptr<RayTracer> specular_tracer;  ///< the whole scene, where it has specular surfaces
  SpecularBackProjection back_projection;      ///< the last render's
  ShadowLayout layout;
  IsmPointPools points;
  DirVkTimings timings;
  std::uint32_t vpl_count = 0;
  std::vector<float> cpu_ism_atlas;  // of the last render when it shaded on the CPU
  // The G-buffer read back on demand (once per render; the images are reused frame to frame).
  GBuffer last_gbuffer;
  bool last_gbuffer_current = false;
  // Where the G-buffer and the shadow atlas are copied when the host cannot map them.
  std::vector<float> gbuffer_copy, shadow_atlas_copy;

  /// The device buffer's first `floats` floats for the host to read: the mapped memory itself
  /// where the device's memory is host-visible (lavapipe, integrated GPUs), else a copy in `copy`.
  std::span<const float> host_view(const vk::VulkanBuffer& buffer, std::size_t floats, std::vector<float>& copy) {
    if (const std::span<const std::byte> mapped = buffer.mapped_bytes(); mapped.size() >= floats * sizeof(float))
      return {reinterpret_cast<const float*>(mapped.data()), floats};
    copy.resize(floats);
    context.transfer().download(buffer, std::as_writable_bytes(std::span(copy)));
    return copy;
  }

  // Steps 3-5 (ISMs, shading, merge) into `cmd`.
  void record_shading(VkCommandBuffer cmd, const ShadeParams& params, const DirRenderOptions& options) {
    Impl& d = *this;
    d.timers[2].start(cmd);
    d.ism.record(cmd, *d.vpls, d.vpl_count, params.emitter_count, options.ism);
    d.timers[2].stop(cmd);
    vk::compute_barrier(cmd);
    d.shade_set = {};
    d.shade_set = d.shade.bind({&d.gbuffer_buffer, &*d.materials, &*d.lights, &*d.views, &d.shadow_maps.atlas(),
                                &*d.vpls, &d.ism.atlas(), &d.shaded, &*d.textures});
    const auto n = static_cast<std::uint32_t>(options.interleave);
    d.timers[3].start(cmd);
    d.shade.dispatch(cmd, d.shade_set, params, vk::ComputePipeline::group_count((params.width + n - 1) / n * n, 8),
                     vk::ComputePipeline::group_count((params.height + n - 1) / n * n, 8));
    d.timers[3].stop(cmd);
    vk::compute_barrier(cmd);
    d.timers[4].start(cmd);
    d.merge.dispatch(cmd, d.merge_set, detail::MergeParams{params.width, params.height, n},
                     vk::ComputePipeline::group_count(params.width, 8), vk::ComputePipeline::group_count(params.height, 8));
    d.timers[4].stop(cmd);
  }
};

struct DirRendererVk::TimedIsmAtlas {
  std::vector<float> texels;
  double ms = 0.0;
};

DirRendererVk::DirRendererVk(vk::VulkanContext& context, int width, int height) {
  if (width <= 0 || height <= 0) throw Error("the render size must be positive");
  impl_ = std::make_unique<Impl>(context, width, height);
}

DirRendererVk::~DirRendererVk() = default;

void DirRendererVk::set_scene(const MrScene& scene, const DirRenderOptions& options) {
  Impl& d = *impl_;
  scene.validate();
  d.gbuffer.set_scene(scene);
  d.shadow_maps.set_scene(scene);
  d.layout = plan_shadow_views(scene, options.shadow_tile);
  d.points = sample_ism_points(scene, options.ism);
  d.ism.set_points(d.points);
  if (std::vector<std::shared_ptr<const Texture>> textures = material_textures(scene);
      textures != d.uploaded_textures || !d.textures) {
    PackedTextures packed = pack_textures(textures);
    d.upload(d.textures, packed.words);
    d.texture_headers = std::move(packed.material_headers);
    d.uploaded_textures = std::move(textures);
  }
  d.upload(d.materials, pack_materials(scene, d.texture_headers));
  d.upload(d.lights, pack_lights(scene, d.layout));
  d.upload(d.views, pack_views(d.layout));
  // The secondary rays of specular surfaces need the whole scene on the CPU (specular_gbuffer.h).
  d.specular_tracer = has_specular_surfaces(scene) ? std::make_unique<RayTracer>(scene) : nullptr;
  // Kept for the shading, which reads the materials, lights and environment; the meshes are on
  // the device already (copying them would copy the whole reconstruction every frame).
  d.scene = MrScene{scene.materials, {}, scene.lights, scene.environment, {}};
}

DifferentialImages DirRendererVk::render(const MrCamera& camera, std::span<const Vpl> vpls, const DirRenderOptions& options) {
  Impl& d = *impl_;
  if (!d.scene) throw LogicError("DirRendererVk::set_scene must come before render");
  if (options.shadow_tile != d.layout.tile) throw Error("DirRendererVk: the shadow tile differs from set_scene's");
  if (!(options.shading.min_distance > 0.f)) throw Error("the VPL clamp distance must be positive");
  if (options.interleave < 1 || options.interleave > 8) throw Error("the interleave factor must be 1 to 8");
  d.upload(d.vpls, pack_vpls(vpls));
  d.vpl_count = static_cast<std::uint32_t>(vpls.size());
  d.last_gbuffer_current = false;
  d.back_projection = {};

  const Eigen::Vector3f centre = camera.camera_to_world.translation().cast<float>();
  const Eigen::Vector3f environment = d.scene->environment.radiance;
  const ShadeParams params{
      static_cast<std::uint32_t>(d.width),
      static_cast<std::uint32_t>(d.height),
      static_cast<std::uint32_t>(d.scene->lights.size()),
      d.vpl_count,
      d.layout.tile,
      d.layout.columns,
      d.layout.rows(),
      options.ism.tile,
      options.shading.min_distance,
      shade_flags(options),
      static_cast<std::uint32_t>(options.interleave),
      static_cast<std::uint32_t>(emitter_count(vpls)),
      {centre.x(), centre.y(), centre.z(), 1.f},
      {environment.x(), environment.y(), environment.z(), options.shading.real_depth_noise_sigmas},
      {d.points.virtual_bounds.x(), d.points.virtual_bounds.y(), d.points.virtual_bounds.z(),
       d.points.virtual_bounds.w()},
      {d.points.scene_bounds.x(), d.points.scene_bounds.y(), d.points.scene_bounds.z(), d.points.scene_bounds.w()}};
  const bool cpu_shading =
      options.backend == DirBackend::Cpu || (options.backend == DirBackend::Auto && d.context.is_cpu_device());
  // The CPU's ISMs need only the VPLs and the point pools, not the device's maps: they are splatted
  // on a thread of their own while the device rasterises the G-buffer and the shadow maps, in
  // whatever time lavapipe's rasteriser leaves a core idle (dir/frame_640x480_64vpl: 110-130 ->
  // 106-112 ms; in the replay, whose larger meshes keep both cores busy, no measurable gain).
  std::future<TimedIsmAtlas> cpu_ism;
  if (cpu_shading)
    cpu_ism = std::async(std::launch::async, [&d, vpls, &options] {
      const auto start = std::chrono::steady_clock::now();
      TimedIsmAtlas ism{ism_atlas_cpu(d.points, vpls, options.ism), 0.0};
      ism.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      return ism;
    });
  d.context.submit([&](VkCommandBuffer cmd) {
    d.timers[5].start(cmd);
    d.timers[0].start(cmd);
    d.gbuffer.record(cmd, camera, d.gbuffer_buffer);
    d.timers[0].stop(cmd);
    d.timers[1].start(cmd);
    d.shadow_maps.record(cmd, d.layout);
    d.timers[1].stop(cmd);
    if (!cpu_shading) d.record_shading(cmd, params, options);
    d.timers[5].stop(cmd);
  });
  const auto ms = [&](std::size_t k) { return d.timers[k].elapsed_ms().value_or(0.0); };
  d.timings = {ms(0), ms(1), ms(2), ms(3), ms(4), ms(5), cpu_shading};
  DifferentialImages out = cpu_shading ? shade_on_cpu(camera, vpls, cpu_ism, options) : download_images();
  if (d.specular_tracer) {
    // Reflective and refractive surfaces: their secondary G-buffers traced and shaded on the CPU
    // from this frame's maps (specular_shading.h).
    const auto start = std::chrono::steady_clock::now();
    d.back_projection = add_specular_light(out, *d.specular_tracer, camera, last_gbuffer(), d.layout,
                                           shadow_atlas_view(), vpls, last_ism_atlas(), d.points, options);
    d.timings.specular_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    d.timings.total_ms += d.timings.specular_ms;
  }
  return out;
}

DifferentialImages DirRendererVk::download_images() const {
  Impl& d = *impl_;
  std::vector<float> radiance(static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height) * 16);
  d.context.transfer().download(d.output, std::as_writable_bytes(std::span(radiance)));
  DifferentialImages out{RadianceImage(d.width, d.height), RadianceImage(d.width, d.height), CoverageImage(d.width, d.height), 1,
                         RadianceImage(d.width, d.height), RadianceImage(d.width, d.height)};
  for (std::size_t i = 0; i < out.real.pixels().size(); ++i) {
    const float* p = &radiance[16 * i];
    out.real_virtual.pixels()[i] = {p[0], p[1], p[2]};
    out.virtual_coverage.pixels()[i] = p[3];
    out.real.pixels()[i] = {p[4], p[5], p[6]};
    out.indirect_real_virtual.pixels()[i] = {p[8], p[9], p[10]};
    out.indirect_real.pixels()[i] = {p[12], p[13], p[14]};
  }
  return out;
}

DifferentialImages DirRendererVk::shade_on_cpu(const MrCamera& camera, std::span<const Vpl> vpls,
                                               std::future<TimedIsmAtlas>& ism, const DirRenderOptions& options) {
  Impl& d = *impl_;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  TimedIsmAtlas atlas = ism.get();
  d.cpu_ism_atlas = std::move(atlas.texels);
  const auto ism_done = Clock::now();
  DifferentialImages out =
      shade_dir_from_maps(last_gbuffer(), *d.scene, camera.camera_to_world.translation().cast<float>(), d.layout,
                          shadow_atlas_view(), vpls, d.cpu_ism_atlas, d.points, options);
  const auto done = Clock::now();
  // ism_ms: the splatting's own time, though most of it overlapped the device's passes; total_ms
  // counts only what it added after them.
  d.timings.ism_ms = atlas.ms;
  d.timings.shading_ms = std::chrono::duration<double, std::milli>(done - ism_done).count();
  d.timings.total_ms += std::chrono::duration<double, std::milli>(done - start).count();
  return out;
}

const DirVkTimings& DirRendererVk::last_timings() const { return impl_->timings; }
const ShadowLayout& DirRendererVk::shadow_layout() const { return impl_->layout; }
const SpecularBackProjection& DirRendererVk::last_back_projection() const { return impl_->back_projection; }
const IsmPointPools& DirRendererVk::ism_points() const { return impl_->points; }

const GBuffer& DirRendererVk::last_gbuffer() const {
  // Read back once per render: the CPU backend shades from it and the DIR stage smooths with it.
  Impl& d = *impl_;
  if (!d.last_gbuffer_current) {
    // The texture coordinates (the last third) only when a material has a texture to sample.
    std::size_t floats = d.gbuffer_buffer.size_bytes() / sizeof(float);
    if (!d.scene || !has_textures(*d.scene)) floats = floats / 12 * 8;
    GBufferVk::unpack_into(d.host_view(d.gbuffer_buffer, floats, d.gbuffer_copy), d.width, d.height, d.last_gbuffer);
    d.last_gbuffer_current = true;
  }
  return d.last_gbuffer;
}

std::span<const float> DirRendererVk::shadow_atlas_view() const {
  Impl& d = *impl_;
  return d.host_view(
      d.shadow_maps.atlas(),
      static_cast<std::size_t>(d.layout.atlas_width()) * static_cast<std::size_t>(d.layout.atlas_height()),
      d.shadow_atlas_copy);
}

std::vector<float> DirRendererVk::last_shadow_atlas() const {
  const std::span<const float> view = shadow_atlas_view();
  return {view.begin(), view.end()};
}

std::vector<float> DirRendererVk::last_ism_atlas() const {
  if (impl_->timings.cpu_shading) return impl_->cpu_ism_atlas;
  std::vector<float> data(impl_->ism.atlas().size_bytes() / sizeof(float));
  impl_->context.transfer().download(impl_->ism.atlas(), std::as_writable_bytes(std::span(data)));
  return data;
}

}  // namespace relight::render
