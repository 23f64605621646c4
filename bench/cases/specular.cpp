// DIR with reflective and refractive objects (render/dir/specular_gbuffer.h, specular_shading.h;
// Knecht et al., TVCG 2013) against the path tracer, on the synthetic room at 640x480: the glass
// pebble and the aluminium bottle on the table under a real spot light, 256 light samples.
// dir/specular_640x480: `ms` per frame (VPLs included) of the Vulkan renderer with both objects,
// the baseline the same frame without them ("dir_without_specular_objects"), interleaved; stages_ms
// per step (specular: the caustic photons traced and gathered, the secondary G-buffers traced and
// shaded, on the CPU); by_photon_count: the caustic error for 1k to 64k photons per light;
// caustic_delta_rel_error_fixed_radius: the error when every photon is spread over the widest disc
// (caustic_photons.h); high_budget: the caustic error and the frame's ms with 262144 photons per
// light and from the VPLs and 1024 light samples; by_vpl_photon_count:
// caustic_region_error_without_caustics and the specular step's ms for 0 to 64k photons from the
// VPLs (the indirect light that mirrors and glass pass on, caustic_photons.h). Errors against the
// path tracer (1 bounce, caustics on, kReferenceSpp samples per pixel):
//   specular_delta_rel_error: sum |TM(L_rv) - TM(L_rv_ref)| / sum |TM(L_rv_ref)| over the
//     pixels inside the mirror and glass (what they show where the camera image cannot be
//     back-projected; elsewhere the composite takes the camera's own colours);
//   caustic_delta_rel_error: the mean relative error of DeltaL = TM(L_rv) - TM(L_r) where the
//     path tracer's caustics change DeltaL by more than 0.02 (its images with and without caustic
//     light paths);
//   caustic_reference_noise: the same error of a second reference frame (another seed): the
//     floor that the reference's noise sets under caustic_delta_rel_error;
//   caustic_energy_ratio: what our caustics add to DeltaL over that region (64k photons per
//     light, our frame with and without them) over what the reference's add (1 = as much);
//   caustic_region_error_without_caustics: the same region's error of our frame without the
//     lights' photons against the reference without caustic paths (DIR's shadows and VPLs
//     there, and the VPLs' photons: light from a diffuse surface through a mirror or glass is a
//     camera path's, L D S D E, not a caustic). Not quite like for like: our frame keeps the
//     caustic VPLs (vpl.h: light through glass leaves its VPL where it lands) and their photons,
//     L S D (S) D E paths, which the reference finds only by its light tracing;
//   composite_rmse: as dir/vs_reference.
#include <chrono>

#include "bench.h"
#include "differential_errors.h"
#include "relight/render/dir/dir_vk.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/synth/trajectory.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/vk/context.h"

namespace {

using namespace relight;

constexpr int kReferenceSpp = 64;

render::MrScene room(bool with_specular_objects) {
  render::MrScene scene = truth::scene_from_synth(synth::default_indoor_scene());
  scene.environment.radiance.setZero();
  scene.lights.push_back(render::spot_light({0.45f, -0.55f, 1.9f}, Eigen::Vector3f(-0.1f, 0.25f, -1.f).normalized(),
                                            35.f, 25.f, Eigen::Vector3f::Constant(3.f), true));
  if (with_specular_objects) {
    render::add_virtual_model(scene, render::make_glass_pebble(), render::Placement::parse("0.35,-0.2,0.75,30"));
    render::add_virtual_model(scene, render::make_metal_bottle(), render::Placement::parse("0.12,-0.38,0.75,0"));
  }
  return scene;
}

render::MrCamera camera() {
  return {PinholeIntrinsics{}, synth::look_at({1.2, -1.1, 1.35}, {0.25, -0.2, 0.75})};  // Kinect v1, 640x480
}

render::DifferentialImages path_traced(const render::MrScene& scene, const render::MrCamera& view, double caustics,
                                       std::uint64_t seed = 99) {
  render::PathTracerOptions options;
  options.max_bounces = 1;
  options.seed = seed;
  options.caustic_paths_per_pixel = caustics;
  return render::render_reference(scene, view, kReferenceSpp, options);
}

/// specular_delta_rel_error: over the pixels whose 3x3 neighbourhood is all mirror or glass.
double specular_error(const render::DifferentialImages& ours, const render::DifferentialImages& reference,
                      const render::GBuffer& gbuffer, const render::MrScene& scene) {
  const int width = gbuffer.material.width(), height = gbuffer.material.height();
  const auto specular = [&](int x, int y) {
    const std::uint16_t label = gbuffer.material(y, x);
    return label != 0 && scene.materials.at(label - 1u).specular.specular();
  };
  double diff = 0.0, norm = 0.0;
  for (int y = 1; y + 1 < height; ++y)
    for (int x = 1; x + 1 < width; ++x) {
      bool inside = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside = inside && specular(x + dx, y + dy);
      if (!inside) continue;
      const Float3 r = bench::tm(reference.real_virtual(y, x));
      diff += length(bench::tm(ours.real_virtual(y, x)) - r);
      norm += length(r);
    }
  return norm > 0.0 ? diff / norm : 0.0;
}

/// Whether pixel i is a real surface whose DeltaL the reference's caustics change by > 0.02.
bool in_caustic_region(const render::DifferentialImages& reference, const render::DifferentialImages& without_caustics,
                       std::size_t i) {
  if (reference.virtual_coverage.pixels()[i] > 0.f) return false;
  const auto delta = [i](const render::DifferentialImages& images) {
    return bench::tm(images.real_virtual.pixels()[i]) - bench::tm(images.real.pixels()[i]);
  };
  return length(delta(reference) - delta(without_caustics)) > 0.02f;
}

/// caustic_delta_rel_error and how many pixels the caustics change.
/// `compared_with` (default: the reference) is what `ours` is measured against over that region.
std::pair<double, int> caustic_error(const render::DifferentialImages& ours,
                                     const render::DifferentialImages& reference,
                                     const render::DifferentialImages& without_caustics,
                                     const render::DifferentialImages* compared_with = nullptr) {
  const render::DifferentialImages& truth = compared_with ? *compared_with : reference;
  const auto delta = [](const render::DifferentialImages& images, std::size_t i) {
    return bench::tm(images.real_virtual.pixels()[i]) - bench::tm(images.real.pixels()[i]);
  };
  double diff = 0.0, norm = 0.0;
  int pixels = 0;
  for (std::size_t i = 0; i < reference.real.size(); ++i) {
    if (!in_caustic_region(reference, without_caustics, i)) continue;
    diff += length(delta(ours, i) - delta(truth, i));
    norm += length(delta(truth, i));
    ++pixels;
  }
  return {norm > 0.0 ? diff / norm : 0.0, pixels};
}

/// Sum over the caustic region of what the caustics add to DeltaL in ours over the same in the
/// reference (all channels).
double caustic_energy_ratio(const render::DifferentialImages& ours, const render::DifferentialImages& ours_without,
                            const render::DifferentialImages& reference,
                            const render::DifferentialImages& without_caustics) {
  const auto delta = [](const render::DifferentialImages& images, std::size_t i) {
    const Float3 d = bench::tm(images.real_virtual.pixels()[i]) - bench::tm(images.real.pixels()[i]);
    return static_cast<double>(d.x) + d.y + d.z;
  };
  double added = 0.0, reference_added = 0.0;
  for (std::size_t i = 0; i < reference.real.size(); ++i) {
    if (!in_caustic_region(reference, without_caustics, i)) continue;
    added += delta(ours, i) - delta(ours_without, i);
    reference_added += delta(reference, i) - delta(without_caustics, i);
  }
  return reference_added != 0.0 ? added / reference_added : 0.0;
}

bench::Json specular_640x480(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const render::MrCamera view = camera();
  const int width = view.intrinsics.width, height = view.intrinsics.height;
  render::DirRenderOptions dir_options;
  dir_options.shading.min_distance = 0.05f;
  struct Frame {
    render::MrScene scene;
    render::RayTracer tracer;
    render::DirRendererVk renderer;
    render::DifferentialImages images;
    double vpl_ms = 0.0;
    Frame(vk::VulkanContext& context, render::MrScene s, int width, int height, const render::DirRenderOptions& options)
        : scene(std::move(s)), tracer(scene), renderer(context, width, height) {
      renderer.set_scene(scene, options);
    }
    int light_samples = 256;
    void draw(const render::MrCamera& view, const render::DirRenderOptions& options) {
      const auto start = std::chrono::steady_clock::now();
      render::VplOptions vpl_options;
      vpl_options.count = light_samples;
      const std::vector<render::Vpl> vpls = render::generate_vpls(scene, tracer, vpl_options);
      vpl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      images = renderer.render(view, vpls, options);
    }
  };
  Frame ours(*context, room(true), width, height, dir_options);
  Frame baseline(*context, room(false), width, height, dir_options);
  ours.draw(view, dir_options);  // warm-up: pipelines, buffers
  baseline.draw(view, dir_options);
  const bench::Comparison c =
      bench::compare_interleaved([&] { ours.draw(view, dir_options); }, [&] { baseline.draw(view, dir_options); },
                                 std::max(3, options.repetitions / 2));
  bench::Json json = bench::comparison_json(c, "dir_without_specular_objects");
  const render::DirVkTimings& t = ours.renderer.last_timings();
  json["stages_ms"] = {{"vpls", ours.vpl_ms},      {"gbuffer", t.gbuffer_ms}, {"shadow_maps", t.shadow_maps_ms},
                       {"ism", t.ism_ms},          {"shading", t.shading_ms}, {"merge", t.merge_ms},
                       {"specular", t.specular_ms}};

  const render::DifferentialImages reference = path_traced(ours.scene, view, 2.0);
  const render::DifferentialImages without_caustics = path_traced(ours.scene, view, 0.0);
  json["specular_delta_rel_error"] = specular_error(ours.images, reference, ours.renderer.last_gbuffer(), ours.scene);
  const auto [caustic, caustic_pixels] = caustic_error(ours.images, reference, without_caustics);
  json["caustic_delta_rel_error"] = caustic;
  json["caustic_pixels"] = caustic_pixels;
  // The reference's own noise over that region: a second path-traced frame (another seed)
  // measured as if it were ours. The floor under caustic_delta_rel_error at this sample count.
  json["caustic_reference_noise"] =
      caustic_error(path_traced(ours.scene, view, 2.0, 7), reference, without_caustics).first;
  json["composite_rmse"] = bench::compare(ours.images, reference).composite_rmse;
  json["caustic_photons_per_light"] = dir_options.caustics.photons_per_light;
  json["caustic_vpl_photons"] = dir_options.caustics.vpl_photons;
  json["caustic_radius"] = dir_options.caustics.radius;
  json["caustic_min_radius"] = dir_options.caustics.min_radius;
  json["caustic_neighbours"] = dir_options.caustics.neighbours;
  // The caustic error against the photon count (the VPL count stays at 256).
  bench::Json by_photons = bench::Json::array();
  for (const int photons : {1024, 4096, 16384, 32768, 65536}) {
    render::DirRenderOptions more = dir_options;
    more.caustics.photons_per_light = photons;
    ours.draw(view, more);
    by_photons.push_back({{"photons_per_light", photons},
                          {"caustic_delta_rel_error", caustic_error(ours.images, reference, without_caustics).first},
                          {"specular_ms", ours.renderer.last_timings().specular_ms}});
  }
  json["by_photon_count"] = by_photons;
  // How much caustic light we add in that region against the reference (1 = as much): our
  // frame with and without photons against the reference's with and without caustic paths.
  {
    const render::DifferentialImages with_photons = ours.images;  // the last: 64k photons
    render::DirRenderOptions none = dir_options;
    none.caustics.photons_per_light = 0;
    ours.draw(view, none);
    json["caustic_energy_ratio"] = caustic_energy_ratio(with_photons, ours.images, reference, without_caustics);
    json["caustic_region_error_without_caustics"] =
        caustic_error(ours.images, reference, without_caustics, &without_caustics).first;
    bench::Json by_vpl_photons = bench::Json::array();
    for (const int photons : {0, 16384, 65536}) {
      render::DirRenderOptions variant = none;
      variant.caustics.vpl_photons = photons;
      ours.draw(view, variant);
      by_vpl_photons.push_back({{"vpl_photons", photons},
                                {"caustic_region_error_without_caustics",
                                 caustic_error(ours.images, reference, without_caustics, &without_caustics).first},
                                {"specular_ms", ours.renderer.last_timings().specular_ms}});
    }
    json["by_vpl_photon_count"] = by_vpl_photons;
  }
  // The error where the method converges: 262144 photons of each kind and 4 times the light
  // samples.
  {
    render::DirRenderOptions more = dir_options;
    more.caustics.photons_per_light = 262144;
    more.caustics.vpl_photons = 262144;
    ours.light_samples = 1024;
    const auto start = std::chrono::steady_clock::now();
    ours.draw(view, more);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    json["high_budget"] = {{"photons_per_light", more.caustics.photons_per_light},
                           {"vpl_photons", more.caustics.vpl_photons},
                           {"light_samples", ours.light_samples},
                           {"caustic_delta_rel_error", caustic_error(ours.images, reference, without_caustics).first},
                           {"ms", ms}};
    ours.light_samples = 256;
  }
  // The same photons each spread over the widest disc (no adaptation to their density).
  {
    render::DirRenderOptions fixed = dir_options;
    fixed.caustics.min_radius = fixed.caustics.radius;
    ours.draw(view, fixed);
    json["caustic_delta_rel_error_fixed_radius"] = caustic_error(ours.images, reference, without_caustics).first;
  }
  json["width"] = width;
  json["height"] = height;
  json["light_samples"] = 256;
  json["reference_spp"] = kReferenceSpp;
  json["device"] = context->device_info().name;
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("dir/specular_640x480", specular_640x480);
