// Differential instant radiosity against the path tracer (render/reference/dir_exact.h, render/reference/path_tracer.h)
// on the synthetic scene with the shipped pebble on the table, 640x480 (the camera's size; the
// same comparison at 320x240 under "at_320x240"), one indirect bounce in both, the sky switched
// off (DIR lights the environment with directional lights, direct only).
//
// dir/vs_reference: for 64, 256 and 1024 light samples, the mean relative error of the
// differential image DeltaL = TM(L_rv) - TM(L_r) where it matters (|DeltaL_reference| > 0.01:
// shadows and colour bleeding), the composite's RMSE (the camera image being the reference's
// TM(L_r)), and the path tracer's composite RMSE when it gets DIR's wall time (equal time).
// The renderer measured is the Vulkan one (VPL generation included in its time); the CPU DIR
// with exact visibility (reference/dir_exact.h) reports the same fields under "cpu_exact_visibility".
// dir/gbuffer_640x480: the first Vulkan stage of DIR against its ray-cast reference, and the
// anti-aliased outlines on top of it (edge_coverage_ms, with_edges_ratio: goal <= 1.5).
// dir/frame_640x480_64vpl, dir/frame_640x480_256vpl: one whole frame at 640x480 (VPLs on the
// CPU, then G-buffer, shadow maps, ISMs and shading on the GPU), with the GPU time per step.
// dir/one_vs_two_pass: one render writing L_rv and L_r against two renders of the same
// renderer writing one each (what a renderer without the differential pass would need).
// dir/two_bounces_vs_reference: the same comparison at 160x120 against a path tracer with two
// indirect bounces, for DIR (Vulkan, 256 light samples) with one bounce, with two whose second
// bounce is ray traced, and with two found by the point-cone method (vpl.h), its search on the
// CPU and on Vulkan (cone_search_vk.h), and with two from the multiple-bounce light source
// (BounceMethod::PreviousFrame; each run is the next frame of the static scene); median of 3 runs.
// dir/environment_vpls_vs_directional: the room as replay reconstructs it (its depth mesh) with
// the pebble, under a uniform sky (no lamps), the path tracer its truth; DIR lights it with the sky importance-sampled
// into directional lights, 64 reaching the scene as emitter VPLs shadowed by their ISMs (ours, vpl.h) against 8
// shadow-mapped ones (the baseline "directional", what replay's --environment directional runs), at 640x480 with 256
// light samples of bounce VPLs each; ms per frame including the VPLs, errors as dir/vs_reference, and each renderer's
// steps. Also: 8 lights as VPLs and 64 shadow-mapped.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <tuple>
#include <utility>

#include "bench.h"
#include "differential_errors.h"
#include "relight/lights/light_stages.h"
#include "relight/render/dir/dir_vk.h"
#include "relight/render/dir/edge_coverage.h"
#include "relight/render/dir/gbuffer_vk.h"
#include "relight/render/reference/dir_exact.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/depth_mesh.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/render/scene/scene_lights.h"
#include "relight/render/vpl/cone_search_vk.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/vk/context.h"

namespace {

using namespace relight;
using bench::compare;
using bench::Errors;
using Clock = std::chrono::steady_clock;

render::MrScene bench_scene() {
  render::MrScene scene = truth::scene_from_synth(synth::default_indoor_scene());
  scene.environment.radiance.setZero();
  render::add_virtual_model(scene, render::make_glossy_pebble(), render::Placement::parse("0.35,-0.2,0.75,30"));
  return scene;
}

render::MrCamera bench_camera() {
  const Pose pose = synth::look_at({1.2, -1.1, 1.35}, {0.25, -0.1, 0.75});
  return {PinholeIntrinsics{262.5, 262.5, 79.5, 59.5, 160, 120}, pose};
}

struct CurvePoint {
  double ms = 0.0;
  Errors errors;
};

/// Renders with `render(vpls)` for 64, 256 and 1024 light samples; the time includes the VPLs.
template <class Render>
bench::Json vpl_curve(const render::MrScene& scene, const render::DifferentialImages& reference, Render&& render,
                      CurvePoint& at_256) {
  const render::RayTracer tracer(scene);
  bench::Json curve = bench::Json::array();
  for (int count : {64, 256, 1024}) {
    const auto start = Clock::now();
    render::VplOptions vpl_options;
    vpl_options.count = count;
    const std::vector<render::Vpl> vpls = render::generate_vpls(scene, tracer, vpl_options);
    const render::DifferentialImages images = render(vpls);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    const Errors e = compare(images, reference);
    curve.push_back({{"light_samples", count}, {"vpls", vpls.size()}, {"ms", ms}, {"delta_rel_error", e.delta_rel},
                     {"composite_rmse", e.composite_rmse}});
    if (count == 256) at_256 = {ms, e};
  }
  return curve;
}

constexpr int kReferenceSpp = 256;

/// The path tracer's images with `bounces` indirect bounces, kReferenceSpp samples per pixel.
render::DifferentialImages reference_images(const render::MrScene& scene, const render::MrCamera& camera, int bounces) {
  render::PathTracerOptions options;
  options.max_bounces = bounces;
  options.seed = 99;
  return render::render_reference(scene, camera, kReferenceSpp, options);
}

/// DIR on Vulkan for 64/256/1024 light samples against the 1-bounce reference at `camera`'s
/// size, and the path tracer given the 256-sample frame's wall time; with `cpu_curve`, also the
/// CPU DIR with exact visibility.
bench::Json equal_time_comparison(vk::VulkanContext& context, const render::MrScene& scene,
                                  const render::MrCamera& camera, bool cpu_curve) {
  const render::DifferentialImages reference = reference_images(scene, camera, 1);
  render::DirOptions cpu_options;
  cpu_options.min_distance = 0.05f;
  render::DirRenderOptions vk_options;
  vk_options.shading = cpu_options;
  render::DirRendererVk renderer(context, camera.intrinsics.width, camera.intrinsics.height);
  renderer.set_scene(scene, vk_options);
  (void)renderer.render(camera, {}, vk_options);  // warm-up: pipelines, buffers
  CurvePoint vk_256;
  const bench::Json vk_curve = vpl_curve(scene, reference, [&](const std::vector<render::Vpl>& vpls) {
    return renderer.render(camera, vpls, vk_options);
  }, vk_256);

  // The path tracer with the Vulkan renderer's (256 light samples) wall time.
  render::PathTracerOptions pt_options;
  pt_options.max_bounces = 1;
  pt_options.seed = 7;
  render::DifferentialPathTracer pt(scene, pt_options);
  pt.reset(camera);
  pt.render(1 << 20, std::chrono::duration<double, std::milli>(vk_256.ms));
  const Errors pt_errors = compare(pt.images(), reference);
  bench::Json json{{"width", camera.intrinsics.width},
                   {"height", camera.intrinsics.height},
                   {"ms", vk_256.ms},
                   {"delta_rel_error", vk_256.errors.delta_rel},
                   {"composite_rmse", vk_256.errors.composite_rmse},
                   {"pt_equal_time_rmse", pt_errors.composite_rmse},
                   {"pt_equal_time_spp", pt.samples_done()},
                   {"pt_equal_time_delta_rel_error", pt_errors.delta_rel},
                   {"by_vpl_count", vk_curve}};
  if (cpu_curve) {
    const render::RayTracer tracer(scene);
    CurvePoint cpu_256;
    const bench::Json curve = vpl_curve(scene, reference, [&](const std::vector<render::Vpl>& vpls) {
      return render::shade_instant_radiosity(scene, tracer, camera, vpls, cpu_options);
    }, cpu_256);
    json["cpu_exact_visibility"] = {{"ms", cpu_256.ms},
                                    {"delta_rel_error", cpu_256.errors.delta_rel},
                                    {"composite_rmse", cpu_256.errors.composite_rmse},
                                    {"by_vpl_count", curve}};
  }
  return json;
}

render::MrCamera kinect_camera() {
  render::MrCamera camera = bench_camera();
  camera.intrinsics = PinholeIntrinsics{};  // Kinect v1, 640x480
  return camera;
}

bench::Json vs_reference(const bench::Options&) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const render::MrScene scene = bench_scene();
  bench::Json json = equal_time_comparison(*context, scene, kinect_camera(), true);
  json["renderer"] = "dir_vulkan";
  json["device"] = context->device_info().name;
  json["reference_spp"] = kReferenceSpp;
  // The same comparison at a quarter of the pixels, where DIR's fixed costs (shadow maps, ISMs,
  // both independent of the image size) weigh four times as much against the path tracer's.
  render::MrCamera small = bench_camera();
  small.intrinsics = PinholeIntrinsics{525.0, 525.0, 159.5, 119.5, 320, 240};  // bench_camera() at twice the size
  json["at_320x240"] = equal_time_comparison(*context, scene, small, false);
  return json;
}

bench::Json two_bounces_vs_reference(const bench::Options&) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const render::MrScene scene = bench_scene();
  render::MrCamera camera = bench_camera();
  const render::DifferentialImages reference = reference_images(scene, camera, 2);
  const render::RayTracer tracer(scene);
  render::DirRenderOptions vk_options;
  vk_options.shading.min_distance = 0.05f;
  render::DirRendererVk renderer(*context, camera.intrinsics.width, camera.intrinsics.height);
  renderer.set_scene(scene, vk_options);
  (void)renderer.render(camera, {}, vk_options);  // warm-up: pipelines, buffers
  bench::Json json{{"renderer", "dir_vulkan"}, {"device", context->device_info().name}, {"light_samples", 256},
                   {"reference_spp", kReferenceSpp}, {"reference_bounces", 2}};
  render::ConeSearchVk cone_search(*context);
  const auto run = [&](int bounces, render::BounceMethod method, render::ConeSearchVk* gpu = nullptr,
                       int light_samples = 256) {
    render::VplOptions vpl_options;
    vpl_options.count = light_samples;
    vpl_options.bounces = bounces;
    vpl_options.bounce_method = method;
    std::vector<double> ms, vpl_ms;
    Errors errors;
    std::size_t vpl_count = 0;
    // The multiple-bounce light source continues the previous frame's VPLs: a first frame to
    // continue, then every repetition is the next frame of the static scene.
    std::vector<render::Vpl> previous;
    std::vector<Phong> previous_surfaces;
    if (method == render::BounceMethod::PreviousFrame) {
      previous = render::generate_vpls(scene, tracer, vpl_options);
      previous_surfaces = render::vpl_surfaces(scene, previous);
    }
    for (int repetition = 0; repetition < 3; ++repetition) {
      vpl_options.previous_vpls = previous;
      vpl_options.previous_surfaces = previous_surfaces;
      const auto start = Clock::now();
      std::vector<render::Vpl> vpls = render::generate_vpls(scene, tracer, vpl_options, {.cone_search = gpu});
      vpl_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      errors = compare(renderer.render(camera, vpls, vk_options), reference);
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      vpl_count = vpls.size();
      if (method == render::BounceMethod::PreviousFrame) {
        previous_surfaces = render::vpl_surfaces(scene, vpls);
        previous = std::move(vpls);
      }
    }
    std::sort(ms.begin(), ms.end());
    std::sort(vpl_ms.begin(), vpl_ms.end());
    return bench::Json{{"ms", ms[1]}, {"vpl_generation_ms", vpl_ms[1]}, {"vpls", vpl_count},
                       {"delta_rel_error", errors.delta_rel}, {"composite_rmse", errors.composite_rmse}};
  };
  json["one_bounce"] = run(1, render::BounceMethod::RayTraced);
  json["two_bounces_rays"] = run(2, render::BounceMethod::RayTraced);
  json["two_bounces_cone"] = run(2, render::BounceMethod::PointCone);
  json["two_bounces_cone_search_on_vulkan"] = run(2, render::BounceMethod::PointCone, &cone_search);
  // The multiple-bounce light source (vpl.h): a quarter of the 256 samples continue the previous
  // frame's VPLs; and with as many first-bounce samples as the others (341 in all).
  json["two_bounces_previous_frame"] = run(2, render::BounceMethod::PreviousFrame);
  json["two_bounces_previous_frame_341"] = run(2, render::BounceMethod::PreviousFrame, nullptr, 341);
  json["ms"] = json["two_bounces_cone_search_on_vulkan"]["ms"];
  return json;
}

/// dir/frame_640x480_*: VPL generation + one frame (backend Auto: ISMs and shading on the CPU
/// on a software device), against the same frame with every step on Vulkan; median wall times,
/// and the per-step times of the last Auto frame.
bench::Json frame_640x480(const bench::Options& options, int light_samples) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const render::MrScene scene = bench_scene();
  const render::MrCamera camera = kinect_camera();
  const render::RayTracer tracer(scene);
  render::DirRenderOptions automatic, on_gpu;
  on_gpu.backend = render::DirBackend::Gpu;
  render::DirRendererVk renderer(*context, 640, 480);
  renderer.set_scene(scene, automatic);
  render::VplOptions vpl_options;
  vpl_options.count = light_samples;
  std::vector<render::Vpl> vpls;
  double vpl_ms = 0.0;
  render::DirVkTimings t;
  const auto frame = [&](const render::DirRenderOptions& dir_options) {
    const auto start = Clock::now();
    vpls = render::generate_vpls(scene, tracer, vpl_options);
    vpl_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    (void)renderer.render(camera, vpls, dir_options);
  };
  const bench::Comparison c = bench::compare_interleaved(
      [&] {
        frame(automatic);
        t = renderer.last_timings();
      },
      [&] { frame(on_gpu); }, std::max(3, options.repetitions / 2));
  bench::Json json = bench::comparison_json(c, "all_steps_on_vulkan");
  json["fps"] = 1000.0 / c.ms;
  json["vpls"] = vpls.size();
  json["device"] = context->device_info().name;
  json["shading_backend"] = t.cpu_shading ? "cpu" : "vulkan";
  json["stages_ms"] = {{"vpl_generation_cpu", vpl_ms}, {"gbuffer", t.gbuffer_ms}, {"shadow_maps", t.shadow_maps_ms},
                       {"ism", t.ism_ms}, {"shading", t.shading_ms}, {"merge", t.merge_ms}};
  json["interleave"] = automatic.interleave;
  json["shadow_tile"] = automatic.shadow_tile;
  json["ism_tile"] = automatic.ism.tile;
  json["ism_points_per_vpl"] = automatic.ism.points_per_vpl;
  return json;
}

/// dir/one_vs_two_pass: 640x480, 256 light samples, VPLs generated once.
bench::Json one_vs_two_pass(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const render::MrScene scene = bench_scene();
  const render::MrCamera camera = kinect_camera();
  render::DirRenderOptions both;
  render::DirRendererVk renderer(*context, 640, 480);
  renderer.set_scene(scene, both);
  render::VplOptions vpl_options;
  vpl_options.count = 256;
  const std::vector<render::Vpl> vpls = render::generate_vpls(scene, render::RayTracer(scene), vpl_options);
  render::DirRenderOptions rv_only = both, r_only = both;
  rv_only.output = render::DirOutput::RealVirtualOnly;
  r_only.output = render::DirOutput::RealOnly;
  const bench::Comparison c = bench::compare_interleaved([&] { (void)renderer.render(camera, vpls, both); },
                                                         [&] {
                                                           (void)renderer.render(camera, vpls, rv_only);
                                                           (void)renderer.render(camera, vpls, r_only);
                                                         },
                                                         options.repetitions);
  bench::Json json = bench::comparison_json(c, "two_pass");
  json["vpls"] = vpls.size();
  json["device"] = context->device_info().name;
  return json;
}

/// dir/gbuffer_640x480: the rasterised G-buffer of the synthetic scene with the pebble (about
/// 12k triangles) against the ray-cast one (Embree, all threads): wall time including the read
/// back, and the draw's GPU time.
bench::Json gbuffer_640x480(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const render::MrScene scene = bench_scene();
  const render::MrCamera camera = kinect_camera();
  render::GBufferVk renderer(*context, 640, 480);
  renderer.set_scene(scene);
  const render::RayTracer tracer(scene);
  const bench::Comparison c = bench::compare_interleaved([&] { (void)renderer.render(camera); },
                                                         [&] { (void)render::gbuffer_cpu(tracer, camera); },
                                                         options.repetitions);
  bench::Json json = bench::comparison_json(c, "embree_ray_cast");
  json["gpu_ms"] = renderer.last_gpu_ms();
  json["device"] = context->device_info().name;
  // The anti-aliased outlines on top (edge_coverage.h): the virtual meshes' tracer and 16 rays
  // per outline pixel; goal: G-buffer + outlines <= 1.5 x the G-buffer alone.
  const render::GBuffer gbuffer = render::gbuffer_cpu(tracer, camera);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  PositionMap real(640, 480, Float3{nan, nan, nan});
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  const Pose world_to_camera = camera.camera_to_world.inverse();
  for (int r = 0; r < 480; ++r)
    for (int col = 0; col < 640; ++col) {
      const Eigen::Vector3f d =
          (camera.camera_to_world.linear() * camera.intrinsics.ray(col, r).normalized()).cast<float>();
      if (const auto hit = tracer.intersect(render::Layer::Real, origin, d)) {
        const Eigen::Vector3d p = world_to_camera * hit->point.cast<double>();
        real(r, col) = {float(p.x()), float(p.y()), float(p.z())};
      }
    }
  render::CoverageImage coverage(640, 480);
  int outline = 0;
  const double edge_ms = bench::median_ms(
      [&] {
        const render::RayTracer virtual_tracer(render::virtual_part(scene), render::RayTracer::Build::Fast);
        outline = render::refine_edge_coverage(coverage, gbuffer, real, virtual_tracer, camera);
      },
      options.repetitions);
  const render::RayTracer prebuilt(render::virtual_part(scene), render::RayTracer::Build::Fast);
  json["edge_rays_ms"] = bench::median_ms(
      [&] { outline = render::refine_edge_coverage(coverage, gbuffer, real, prebuilt, camera); }, options.repetitions);
  json["edge_outline_ms"] = bench::median_ms([&] { (void)render::outline_pixels(gbuffer); }, options.repetitions);
  json["edge_coverage_ms"] = edge_ms;
  json["outline_pixels"] = outline;
  json["with_edges_ratio"] = (c.ms + edge_ms) / c.ms;
  return json;
}

/// The real scene as the product sees it: the depth mesh (stride 2, as the DIR stage makes it)
/// of the synthetic room seen from `camera`, with the room's materials, and the pebble; no
/// lights. Its shadow maps rasterise what replay's do (~150k triangles), not the room's few
/// analytic shapes.
render::MrScene reconstructed_scene(const render::MrCamera& camera) {
  const synth::Scene room = synth::default_indoor_scene();
  render::MrScene scene = truth::scene_from_synth(room);
  scene.meshes.clear();
  scene.lights.clear();
  scene.environment.radiance.setZero();
  const synth::RenderedFrame frame = synth::render_frame(room, camera.intrinsics, camera.camera_to_world);
  render::DepthMeshMaterials materials;
  materials.labels = &frame.material;
  materials.material_of_label.push_back(0);  // nothing hit: no triangle uses it
  for (std::uint32_t m = 0; m < room.materials.size(); ++m) materials.material_of_label.push_back(m);
  render::TriangleMesh mesh =
      render::mesh_from_positions(render::positions_from_depth(frame.depth, camera.intrinsics), &frame.normals,
                                  camera.camera_to_world, materials, {.stride = 2});
  mesh.name = "reconstruction";
  scene.meshes.push_back(std::move(mesh));
  render::add_virtual_model(scene, render::make_glossy_pebble(), render::Placement::parse("0.35,-0.2,0.75,30"));
  return scene;
}

/// The reconstructed scene under a uniform sky of radiance `sky`: the truth's scene.
render::MrScene sky_scene(const render::MrCamera& camera, float sky) {
  render::MrScene scene = reconstructed_scene(camera);
  scene.environment.radiance.setConstant(sky);
  return scene;
}

/// The bench scene without its lamps, lit by the uniform sky importance-sampled into `count`
/// directional lights, through emitter VPLs when `through_vpl`.
render::MrScene sampled_sky_scene(const render::MrCamera& camera, float sky, int count, bool through_vpl) {
  render::MrScene scene = reconstructed_scene(camera);
  RadianceImage probe(128, 64);
  for (Float3& texel : probe.pixels()) texel = {sky, sky, sky};
  lights::LightExtractionOptions extraction;
  extraction.lights = count;
  extraction.calibration = lights::ProbeCalibration::equirectangular();
  render::add_lights(scene, lights::extract_lights(probe, extraction));
  for (render::MrLight& light : scene.lights) light.through_vpl = through_vpl;
  return scene;
}

bench::Json environment_vpls_vs_directional(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  constexpr float kSky = 1.f;
  const render::MrCamera camera = kinect_camera();
  const render::DifferentialImages reference = reference_images(sky_scene(camera, kSky), camera, 1);
  render::DirRenderOptions dir_options;
  dir_options.shading.min_distance = 0.05f;
  dir_options.shadow_tile = 256;  // replay's, for its several soft probe lights
  struct Variant {
    render::MrScene scene;
    std::unique_ptr<render::DirRendererVk> renderer;
    render::RayTracer tracer;
    Errors errors;
    render::DirVkTimings timings;
    std::size_t shadow_views = 0;
    Variant(vk::VulkanContext& context, render::MrScene s, const render::MrCamera& camera,
            const render::DirRenderOptions& options)
        : scene(std::move(s)),
          renderer(std::make_unique<render::DirRendererVk>(context, camera.intrinsics.width, camera.intrinsics.height)),
          tracer(scene) {
      renderer->set_scene(scene, options);
      shadow_views = renderer->shadow_layout().views.size();
    }
    void frame(const render::MrCamera& camera, const render::DirRenderOptions& options,
               const render::DifferentialImages& reference) {
      render::VplOptions vpl_options;
      vpl_options.count = 256;
      errors = compare(renderer->render(camera, render::generate_vpls(scene, tracer, vpl_options), options), reference);
      timings = renderer->last_timings();
    }
    [[nodiscard]] bench::Json steps() const {
      return {{"shadow_maps", timings.shadow_maps_ms},
              {"ism", timings.ism_ms},
              {"shading", timings.shading_ms},
              {"merge", timings.merge_ms}};
    }
  };
  Variant ours(*context, sampled_sky_scene(camera, kSky, 64, true), camera, dir_options);
  Variant baseline(*context, sampled_sky_scene(camera, kSky, 8, false), camera, dir_options);
  const bench::Comparison c = bench::compare_interleaved([&] { ours.frame(camera, dir_options, reference); },
                                                         [&] { baseline.frame(camera, dir_options, reference); },
                                                         std::max(3, options.repetitions / 2));
  bench::Json json = bench::comparison_json(c, "directional");
  json["delta_rel_error"] = ours.errors.delta_rel;
  json["baseline_delta_rel_error"] = baseline.errors.delta_rel;
  json["error_ratio"] = ours.errors.delta_rel / baseline.errors.delta_rel;
  json["composite_rmse"] = ours.errors.composite_rmse;
  json["baseline_composite_rmse"] = baseline.errors.composite_rmse;
  json["lights"] = 64;
  json["baseline_lights"] = 8;
  json["baseline_shadow_views"] = baseline.shadow_views;
  json["stages_ms"] = ours.steps();
  json["baseline_stages_ms"] = baseline.steps();
  // The other two corners: light count and mechanism apart.
  for (const auto& [name, count, through_vpl] :
       {std::tuple{"vpls_8", 8, true}, std::tuple{"directional_64", 64, false}}) {
    Variant other(*context, sampled_sky_scene(camera, kSky, count, through_vpl), camera, dir_options);
    const double ms = bench::median_ms([&] { other.frame(camera, dir_options, reference); }, 3);
    json[name] = {{"ms", ms},
                  {"delta_rel_error", other.errors.delta_rel},
                  {"composite_rmse", other.errors.composite_rmse},
                  {"shadow_views", other.shadow_views},
                  {"stages_ms", other.steps()}};
  }
  json["width"] = camera.intrinsics.width;
  json["height"] = camera.intrinsics.height;
  json["light_samples"] = 256;
  json["reference_spp"] = kReferenceSpp;
  json["device"] = context->device_info().name;
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("dir/vs_reference", vs_reference);
RELIGHT_BENCH_CASE("dir/environment_vpls_vs_directional", environment_vpls_vs_directional);
RELIGHT_BENCH_CASE("dir/gbuffer_640x480", gbuffer_640x480);
RELIGHT_BENCH_CASE("dir/frame_640x480_64vpl", [](const bench::Options& o) { return frame_640x480(o, 64); });
RELIGHT_BENCH_CASE("dir/frame_640x480_256vpl", [](const bench::Options& o) { return frame_640x480(o, 256); });
RELIGHT_BENCH_CASE("dir/one_vs_two_pass", one_vs_two_pass);
RELIGHT_BENCH_CASE("dir/two_bounces_vs_reference", two_bounces_vs_reference);
