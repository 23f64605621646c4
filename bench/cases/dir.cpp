// Differential instant radiosity against the path tracer (render/dir_cpu.h, render/path_tracer.h)
// on the synthetic scene with the shipped pebble on the table, 160x120, one indirect bounce in
// both, the sky switched off (DIR lights the environment with directional lights, direct only).
//
// dir/vs_reference: for 64, 256 and 1024 light samples, the mean relative error of the
// differential image DeltaL = TM(L_rv) - TM(L_r) where it matters (|DeltaL_reference| > 0.01:
// shadows and colour bleeding), the composite's RMSE (the camera image being the reference's
// TM(L_r)), and the path tracer's composite RMSE when it gets DIR's wall time (equal time).
// The renderer measured here is DIR's CPU reference with exact visibility; the Vulkan renderer
// will report into the same fields.
// dir/gbuffer_640x480: the first Vulkan stage of DIR against its ray-cast reference.
#include <chrono>
#include <cmath>

#include "bench.h"
#include "relight/render/dir_cpu.h"
#include "relight/render/gbuffer_vk.h"
#include "relight/render/path_tracer.h"
#include "relight/render/procedural_models.h"
#include "relight/render/scene_from_synth.h"
#include "relight/synth/trajectory.h"
#include "relight/vk/context.h"

namespace {

using namespace relight;
using Clock = std::chrono::steady_clock;

render::MrScene bench_scene() {
  render::MrScene scene = render::scene_from_synth(synth::default_indoor_scene());
  scene.environment.radiance.setZero();
  render::add_virtual_model(scene, render::make_glossy_pebble(), render::Placement::parse("0.35,-0.2,0.75,30"));
  return scene;
}

render::MrCamera bench_camera() {
  const Pose pose = synth::look_at({1.2, -1.1, 1.35}, {0.25, -0.1, 0.75});
  return {PinholeIntrinsics{262.5, 262.5, 79.5, 59.5, 160, 120}, pose};
}

float tm(float x) { return std::clamp(x, 0.f, 1.f); }

Float3 tm(const Float3& c) { return {tm(c.x), tm(c.y), tm(c.z)}; }

/// Composite in camera-linear space, the camera image being `camera_real` (TM of a real image).
Float3 composite(const render::DifferentialImages& images, const RadianceImage& camera_real, std::size_t i) {
  const float c = images.virtual_coverage.pixels()[i];
  const Float3 with = tm(images.real_virtual.pixels()[i]);
  const Float3 delta = with - tm(images.real.pixels()[i]);
  return c * with + (1.f - c) * (tm(camera_real.pixels()[i]) + delta);
}

struct Errors {
  double delta_rel = 0.0;
  double composite_rmse = 0.0;
};

Errors compare(const render::DifferentialImages& ours, const render::DifferentialImages& reference) {
  double diff = 0.0, norm = 0.0, squared = 0.0;
  for (std::size_t i = 0; i < ours.real.size(); ++i) {
    const Float3 c = composite(ours, reference.real, i) - composite(reference, reference.real, i);
    squared += dot(c, c);
    if (ours.virtual_coverage.pixels()[i] > 0.f || reference.virtual_coverage.pixels()[i] > 0.f) continue;
    const Float3 d_ref = tm(reference.real_virtual.pixels()[i]) - tm(reference.real.pixels()[i]);
    if (length(d_ref) <= 0.01f) continue;
    const Float3 d_ours = tm(ours.real_virtual.pixels()[i]) - tm(ours.real.pixels()[i]);
    diff += length(d_ours - d_ref);
    norm += length(d_ref);
  }
  return {norm > 0.0 ? diff / norm : 0.0, std::sqrt(squared / (3.0 * static_cast<double>(ours.real.size())))};
}

bench::Json vs_reference(const bench::Options&) {
  const render::MrScene scene = bench_scene();
  const render::MrCamera camera = bench_camera();
  render::PathTracerOptions pt_options;
  pt_options.max_bounces = 1;
  pt_options.seed = 99;
  const int reference_spp = 1024;
  const render::DifferentialImages reference = render::render_reference(scene, camera, reference_spp, pt_options);
  const render::RayTracer tracer(scene);
  bench::Json curve = bench::Json::array();
  double ms_256 = 0.0;
  Errors errors_256;
  for (int count : {64, 256, 1024}) {
    const auto start = Clock::now();
    render::VplOptions vpl_options;
    vpl_options.count = count;
    const std::vector<render::Vpl> vpls = render::generate_vpls(scene, tracer, vpl_options);
    render::DirOptions options;
    options.min_distance = 0.05f;
    const render::DifferentialImages dir = render::shade_instant_radiosity(scene, tracer, camera, vpls, options);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    const Errors e = compare(dir, reference);
    curve.push_back({{"light_samples", count}, {"vpls", vpls.size()}, {"ms", ms}, {"delta_rel_error", e.delta_rel},
                     {"composite_rmse", e.composite_rmse}});
    if (count == 256) {
      ms_256 = ms;
      errors_256 = e;
    }
  }
  // The path tracer with DIR's (256 light samples) wall time.
  pt_options.seed = 7;
  render::DifferentialPathTracer pt(scene, pt_options);
  pt.reset(camera);
  pt.render(1 << 20, std::chrono::duration<double, std::milli>(ms_256));
  const Errors pt_errors = compare(pt.images(), reference);
  return {{"renderer", "dir_cpu_exact_visibility"},
          {"ms", ms_256},
          {"delta_rel_error", errors_256.delta_rel},
          {"composite_rmse", errors_256.composite_rmse},
          {"pt_equal_time_rmse", pt_errors.composite_rmse},
          {"pt_equal_time_spp", pt.samples_done()},
          {"pt_equal_time_delta_rel_error", pt_errors.delta_rel},
          {"reference_spp", reference_spp},
          {"by_vpl_count", curve}};
}

/// dir/gbuffer_640x480: the rasterised G-buffer of the synthetic scene with the pebble (about
/// 12k triangles) against the ray-cast one (Embree, all threads): wall time including the read
/// back, and the draw's GPU time.
bench::Json gbuffer_640x480(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  render::MrScene scene = bench_scene();
  render::MrCamera camera = bench_camera();
  camera.intrinsics = PinholeIntrinsics{};  // Kinect v1, 640x480
  render::GBufferVk renderer(*context, 640, 480);
  renderer.set_scene(scene);
  const render::RayTracer tracer(scene);
  const bench::Comparison c = bench::compare_interleaved([&] { (void)renderer.render(camera); },
                                                         [&] { (void)render::gbuffer_cpu(tracer, camera); },
                                                         options.repetitions);
  bench::Json json = bench::comparison_json(c, "embree_ray_cast");
  json["gpu_ms"] = renderer.last_gpu_ms();
  json["device"] = context->device_info().name;
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("dir/vs_reference", vs_reference);
RELIGHT_BENCH_CASE("dir/gbuffer_640x480", gbuffer_640x480);
