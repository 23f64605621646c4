// `relight render-reference`: the differential path tracer's ground truth for one frame of a
// sequence with a virtual object (render/path_tracer.h), and `relight models`: writes the
// procedural virtual objects shipped in data/models/.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "mixed_reality_scene.h"
#include "option_values.h"
#include "relight/capture/tum_sequence.h"
#include "relight/colormap/color_space.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/core/progress.h"
#include "relight/render/dir/composite.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/depth_mesh.h"
#include "relight/render/scene/model_io.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/render/scene/real_object_carving.h"
#include "relight/render/scene/scene_lights.h"
#include "relight/synth/light_animation.h"
#include "relight/truth/scene_from_synth.h"
#include "tone_map_json.h"

namespace relight::app {

namespace {

namespace fs = std::filesystem;
using render::MrScene;

struct RenderReferenceOptions {
  fs::path sequence;
  int frame = 0;
  fs::path object;
  std::string place;
  std::vector<fs::path> real_objects;
  std::vector<std::string> real_places;
  fs::path lights;
  std::vector<std::string> virtual_lights;
  std::vector<std::string> virtual_spots;
  std::vector<std::string> real_spots;
  int spp = 256;
  double time_budget = 0.0;
  int max_bounces = 4;
  double caustic_paths = 1.0;  ///< caustic light paths per pixel, light and sample (PathTracerOptions)
  std::uint64_t seed = 1;
  int downsample = 1;
  colormap::ToneMapOptions tone_map;  ///< Reinhard's key from this frame's L_rv (nothing to adapt from)
  int threads = 0;
  fs::path out;
  bool quiet = false;
};

/// The real part of the scene: the synthetic scene's exact geometry, or the frame's depth mesh
/// with the lights of --lights.
MrScene real_scene(const RenderReferenceOptions& command, bool synthetic, const capture::TumSequence& sequence,
                   const RgbdFrame& frame) {
  if (synthetic) {
    // The path tracer gets the synthetic scene's exact lights and sky.
    if (!command.lights.empty())
      throw Error("--lights applies to recorded sequences; a synthetic sequence brings its own lights");
    // With a light animation, the lights of this frame (synth/light_animation.h).
    const fs::path scene_json = command.sequence / "scene.json";
    const synth::SequenceLightAnimation animated =
        synth::light_animation_of_scene_json(read_text_file(scene_json), scene_json.string());
    return truth::scene_from_synth(synth::scene_at_frame(synth::default_indoor_scene(), animated.animation,
                                                         command.frame, std::max(animated.frames, command.frame + 1)));
  }
  MrScene scene;
  render::add_lights(scene, real_light_set(command.sequence, command.lights));
  render::DepthMeshMaterials materials;
  materials.material = scene.add_material({{{0.5f, 0.5f, 0.5f}, 0.f, 1.f}, "reconstruction", {0.f, 0.f, 0.f}});
  scene.meshes.push_back(render::mesh_from_positions(render::positions_from_depth(frame.depth, sequence.intrinsics()),
                                                     nullptr, *frame.info.camera_to_world, materials));
  return scene;
}

PinholeIntrinsics downsampled(const PinholeIntrinsics& k, int factor) {
  const double f = factor;
  // Pixel centres are integers: the new pixel 0 covers old pixels 0..factor-1.
  return {k.fx / f, k.fy / f, (k.cx + 0.5) / f - 0.5, (k.cy + 0.5) / f - 0.5, k.width / factor, k.height / factor};
}

/// Box average in linear light (so edges do not darken).
ColorImage downsample_color(const ColorImage& image, int factor) {
  if (factor == 1) return image;
  ColorImage out(image.width() / factor, image.height() / factor);
  for (int row = 0; row < out.height(); ++row)
    for (int col = 0; col < out.width(); ++col) {
      Float3 sum;
      for (int dy = 0; dy < factor; ++dy)
        for (int dx = 0; dx < factor; ++dx) sum += colormap::decode_srgb8(image(row * factor + dy, col * factor + dx));
      out(row, col) = colormap::encode_srgb8((1.f / static_cast<float>(factor * factor)) * sum);
    }
  return out;
}

fs::path sibling(const fs::path& out, const std::string& suffix) {
  fs::path path = out;
  path.replace_filename(out.stem().string() + suffix);
  return path;
}

int run_render_reference(const RenderReferenceOptions& command) {
  if (command.out.extension() != ".exr") throw Error("--out must name an .exr file (L_rv goes there)");
  // Fail on an unwritable destination now, not after minutes of rendering.
  if (const fs::path folder = command.out.parent_path(); !folder.empty()) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec) throw Error("cannot create " + folder.string() + ": " + ec.message());
  }
  const capture::TumSequence sequence = capture::TumSequence::open(command.sequence);
  if (command.frame < 0 || static_cast<std::size_t>(command.frame) >= sequence.size())
    throw Error("frame " + std::to_string(command.frame) + " is out of range: " + command.sequence.string() + " has " +
                std::to_string(sequence.size()) + " frames");
  const RgbdFrame frame = sequence.load(static_cast<std::size_t>(command.frame));
  if (!frame.info.camera_to_world)
    throw Error("frame " + std::to_string(command.frame) + " has no camera pose (groundtruth.txt)");
  const bool synthetic = is_synthetic(command.sequence);
  MrScene scene = real_scene(command, synthetic, sequence, frame);
  const std::size_t depth_mesh = scene.meshes.size() - 1;  // a recorded frame's (real_scene)
  std::string placement_text;
  if (!command.object.empty()) {
    placement_text = command.place;
    if (placement_text.empty()) {
      if (!synthetic) throw Error("--place x,y,z[,yaw[,scale]] is needed to put the object into a recorded scene");
      placement_text = kDefaultSynthPlacement;
    }
    const render::VirtualModel model = load_model_telling_warnings(command.object);
    render::add_virtual_model(scene, model, render::Placement::parse(placement_text));
  }
  // Real mirrors and glass as replay's --real-object puts them: in the real layer, and in place of a
  // recorded frame's depth mesh around them (a synthetic scene's exact geometry has none of them).
  for (const auto& [model, placement] : load_real_objects(command.real_objects, command.real_places)) {
    const std::span<const render::TriangleMesh> object = render::add_real_model(scene, model, placement);
    if (!synthetic) render::remove_triangles_within(scene.meshes[depth_mesh], object, render::kRealObjectMargin);
  }
  for (const std::string& light : command.virtual_lights) scene.lights.push_back(parse_virtual_light(light));
  for (const std::string& spot : command.real_spots) scene.lights.push_back(parse_spot("--real-spot", spot, true));
  for (const std::string& spot : command.virtual_spots) scene.lights.push_back(parse_virtual_spot(spot));
  const render::MrCamera camera{downsampled(sequence.intrinsics(), command.downsample), *frame.info.camera_to_world};
  render::PathTracerOptions options;
  options.max_bounces = command.max_bounces;
  options.seed = command.seed;
  options.threads = command.threads;
  options.caustic_paths_per_pixel = command.caustic_paths;
  render::DifferentialPathTracer tracer(scene, options);
  tracer.reset(camera);

  ProgressBar progress("render-reference spp", command.spp, command.quiet);
  const auto start = std::chrono::steady_clock::now();
  tracer.render(command.spp, std::chrono::duration<double>(command.time_budget), [&](int done, int) { progress.update(done); });
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const render::DifferentialImages images = tracer.images();

  const colormap::ToneMap tone_map =
      colormap::adapt_tone_map(command.tone_map, colormap::scene_luminance(images.real_virtual), nullptr, 0.0);
  const ColorImage composite = render::differential_composite(downsample_color(frame.color, command.downsample),
                                                              images.real_virtual, images.real, images.virtual_coverage,
                                                              tone_map);
  write_radiance(command.out, images.real_virtual);
  write_radiance(sibling(command.out, ".Lr.exr"), images.real);
  write_color(sibling(command.out, ".composite.png"), composite);
  const double mrays = static_cast<double>(tracer.rays_traced()) / 1e6 / seconds;
  nlohmann::ordered_json summary = {{"sequence", fs::absolute(command.sequence).string()},
                                    {"frame", command.frame},
                                    {"width", camera.intrinsics.width},
                                    {"height", camera.intrinsics.height},
                                    {"object", command.object.empty() ? "" : fs::absolute(command.object).string()},
                                    {"placement", placement_text},
                                    {"real_objects", real_objects_json(command.real_objects, command.real_places)},
                                    {"samples_per_pixel", images.samples_per_pixel},
                                    {"max_bounces", command.max_bounces},
                                    {"seed", command.seed},
                                    {"seconds", seconds},
                                    {"rays", tracer.rays_traced()},
                                    {"caustic_light_paths", tracer.light_paths_traced()},
                                    {"mrays_per_s", mrays},
                                    {"tone_map", tone_map_json(command.tone_map, tone_map)},
                                    {"outputs",
                                     {{"L_rv", command.out.filename().string()},
                                      {"L_r", sibling(command.out, ".Lr.exr").filename().string()},
                                      {"composite", sibling(command.out, ".composite.png").filename().string()}}}};
  write_file_atomically(sibling(command.out, ".json"), summary.dump(2) + "\n");
  if (!command.quiet)
    std::cerr << "relight render-reference: " << images.samples_per_pixel << " spp at " << camera.intrinsics.width << "x"
              << camera.intrinsics.height << " in " << seconds << " s (" << mrays << " Mrays/s) -> " << command.out.string()
              << "\n";
  return 0;
}

void register_render_reference(CLI::App& app, Runners& runners) {
  auto options = std::make_shared<RenderReferenceOptions>();
  CLI::App* command = app.add_subcommand(
      "render-reference",
      "Path-trace the ground truth of one frame with a virtual object: L_rv, L_r and the differential composite");
  command->add_option("--sequence", options->sequence, "TUM RGB-D folder (synthetic from `relight synth`, or recorded)")
      ->required();
  command->add_option("--frame", options->frame, "Frame index")->capture_default_str();
  command->add_option("--object", options->object, "Virtual object: .obj, .gltf or .glb");
  command->add_option("--place", options->place,
                      std::string("Object placement x,y,z[,yaw_degrees[,scale]] in the world frame (synthetic default ") +
                          kDefaultSynthPlacement + ")");
  command->add_option(
      "--real-object", options->real_objects,
      "A model of a real mirror or glass, as replay's --real-object (repeatable, one --real-place each)");
  command->add_option("--real-place", options->real_places,
                      "Placement x,y,z[,yaw_degrees[,scale]] of each --real-object in the world frame");
  command->add_option("--lights", options->lights, "Lights JSON (from `relight lights`), needed for recorded sequences");
  command->add_option("--virtual-light", options->virtual_lights,
                      "A virtual point light x,y,z,intensity[,r,g,b] (W/sr; repeat for more)");
  command->add_option("--virtual-spot", options->virtual_spots,
                      "A virtual spot light x,y,z,target_x,target_y,target_z,angle_degrees,intensity[,r,g,b] "
                      "(W/sr on its axis; repeat for more)");
  command->add_option("--real-spot", options->real_spots,
                      "A real spot light (a lamp of the real scene), as --virtual-spot (repeat for more)");
  command->add_option("--spp", options->spp, "Samples per pixel")->check(CLI::Range(1, 1 << 20))->capture_default_str();
  command->add_option("--time-budget", options->time_budget, "Stop after this many seconds (0 = no limit)")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--max-bounces", options->max_bounces, "Indirect bounces")->check(CLI::Range(0, 1000))->capture_default_str();
  command->add_option("--seed", options->seed, "Random seed; same seed and spp, same image")->capture_default_str();
  command
      ->add_option("--caustic-paths", options->caustic_paths,
                   "Light paths per pixel, light and sample that carry the light focused by mirrors and glass "
                   "(caustics; traced only when the scene has such materials; 0 = none)")
      ->check(CLI::Range(0.0, 1024.0))
      ->capture_default_str();
  command->add_option("--downsample", options->downsample, "Render at 1/N of the camera resolution")
      ->check(CLI::IsMember({1, 2, 4, 8}))
      ->capture_default_str();
  add_choice_option(*command, "--tone-map", options->tone_map.op, colormap::kToneOperatorNames,
                    "The composite's tone mapping: exposure (clamp(--exposure * L, 0, 1)) or reinhard (Reinhard's "
                    "operator with --tone-key over this frame's log-average luminance of L_rv), as relight replay");
  command->add_option("--exposure", options->tone_map.exposure, "Tone-mapping exposure for the composite (exposure)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--tone-key", options->tone_map.key, "--tone-map reinhard: the key (0.18: middle grey)")
      ->check(CLI::Range(0.001, 1.0))
      ->default_str("0.18");
  command->add_option("--threads", options->threads, "Render threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  command->add_option("--out", options->out,
                      "L_rv as OUT.exr; beside it OUT.Lr.exr, OUT.composite.png and OUT.json (spp, time, Mrays/s)")
      ->required();
  command->add_flag("--quiet", options->quiet, "No progress or summary on stderr");
  runners[command] = [options] { return run_render_reference(*options); };
}

void register_models(CLI::App& app, Runners& runners) {
  auto out = std::make_shared<fs::path>();
  CLI::App* command = app.add_subcommand("models", "Write the procedural virtual objects (as shipped in data/models/)");
  command->add_option("--out", *out, "Output folder")->required();
  runners[command] = [out] {
    fs::create_directories(*out);
    std::string written;
    for (const render::VirtualModel& model :
         {render::make_glossy_pebble(), render::make_glass_pebble(), render::make_metal_bottle()}) {
      render::save_gltf(*out / (model.name + ".gltf"), model);
      written += model.name + ".gltf, ";
    }
    const render::VirtualModel box = render::make_matte_box();
    render::save_obj(*out / (box.name + ".obj"), box);
    std::cerr << "relight models: wrote " << written << box.name << ".obj/.mtl to " << out->string() << "\n";
    return 0;
  };
}

}  // namespace

void register_render(CLI::App& app, Runners& runners) {
  register_render_reference(app, runners);
  register_models(app, runners);
}

}  // namespace relight::app
