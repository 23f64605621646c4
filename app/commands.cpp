#include "commands.h"

#include <functional>
#include <iostream>
#include <map>
#include <memory>

#include "json_config.h"
#include "mixed_reality_scene.h"
#include "option_values.h"
#include "replay.h"
#include "view_stage.h"

namespace relight::app {

namespace {

void add_compute_options(CLI::App& command, ReplayOptions& options) {
  add_choice_option(command, "--backend", options.backend, vk::kBackendPolicyNames,
                    "auto (per-pixel stages on the CPU when the only Vulkan device is a CPU device), cpu, vulkan");
  command.add_flag_callback(
      "--cpu", [&options] { options.backend = vk::BackendPolicy::ForceCpu; }, "Same as --backend cpu");
  command.add_option("--device", options.device,
                     "Vulkan device: index, type (discrete, integrated, cpu) or part of its name "
                     "(default: $RELIGHT_VK_DEVICE, else the best device)");
  add_choice_option(command, "--geometry", options.geometry, kGeometryMethodNames,
                    "normal estimation: method1 (raw depth, temporally filtered normals) or method2 "
                    "(warped and merged depth, normals from its positions)");
  add_method2_normals_option(command, options);
}

}  // namespace

namespace {

/// --markers and --pose: what replay and graph share of the camera pose.
void add_pose_options(CLI::App& command, ReplayOptions& options) {
  command.add_option("--markers", options.markers,
                     "AprilTag layout for the camera pose: auto (the sequence's scene.json if it has a tag), "
                     "none, or a layout JSON file; writes marker_trajectory.txt")
      ->capture_default_str();
  add_pose_option(command, options);
}

}  // namespace

void add_pose_option(CLI::App& command, ReplayOptions& options) {
  add_choice_option(command, "--pose", options.pose, capture::kPoseSourceNames,
                    "camera pose: auto (the sequence's own poses when it has them, else marker+odometry with a "
                    "marker layout, else odometry), sequence, marker, odometry, marker+odometry; writes "
                    "camera_trajectory.txt");
}

void add_method2_normals_option(CLI::App& command, ReplayOptions& options) {
  add_choice_option(command, "--method2-normals", options.method2_normals, kMethod2NormalsNames,
                    "method2's normals: filtered (method1's temporal filter on the merged depth) or plain "
                    "(stride-1 cross products of the merged positions)");
}

void add_render_options(CLI::App& command, ReplayOptions& options) {
  command.add_option("--object", options.objects, "Virtual object to render into every frame: .obj, .gltf, .glb (repeatable)");
  command.add_option("--place", options.places,
                     std::string("Placement x,y,z[,yaw_degrees[,scale]] per --object, world frame (synthetic default ") +
                         kDefaultSynthPlacement + ")");
  command.add_option("--real-object", options.real_objects,
                     "A model of an object of the real scene - a real mirror or glass, whose depth the camera cannot "
                     "measure - that virtual objects are seen in and virtual lights shine through: .obj, .gltf, .glb "
                     "(repeatable, one --real-place each; it replaces the reconstruction around it)");
  command.add_option("--real-place", options.real_places,
                     "Placement x,y,z[,yaw_degrees[,scale]] of each --real-object, world frame (with markers: the "
                     "marker frame)");
  command.add_option("--place-at", options.places_at,
                     "Placement u,v[,yaw_degrees[,scale]]: stand the object on the surface seen at pixel (u, v) of the "
                     "first frame, its up axis along that surface's normal (repeatable; objects take the --place "
                     "placements first, then --place-at, then --place-on-plane)");
  command.add_option("--place-on-plane", options.places_on_plane,
                     "Placement [yaw_degrees[,scale]]: stand the object on a support plane of the first frame (of the "
                     "up-facing planes in view - a table, the floor - the one with a free spot nearest the image "
                     "centre, at that spot)")
      ->expected(0, 1)
      ->default_str("")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command.add_option("--lights", options.lights,
                     "Lights JSON of `relight lights`: constant real lights instead of a light probe; or `estimate`: "
                     "estimate them from the RGB-D frames (spherical-harmonics environment and the dominant light from "
                     "cast shadows, accumulated in the world frame) for sequences without a probe");
  command.add_option("--probe", options.probe,
                     "Light probe the real lights are extracted from every frame: a folder with probe.txt "
                     "(\"timestamp filename\" lines), such a list, one image (.hdr, .exr, or 8-bit .png/.jpg), a video "
                     "file, or a camera (/dev/videoN or N). Default: the sequence's probe.txt or probe.hdr");
  ProbeInputOptions& probe = options.probe_input;
  command
      .add_option("--probe-rotation", probe.rotation_degrees,
                  "Probe-to-world rotation rx,ry,rz in degrees (x, then y, then z); default: the probe looks up "
                  "along world +z with its image x along world x")
      ->expected(3)
      ->delimiter(',');
  command
      .add_option("--probe-position", probe.position,
                  "Where the probe camera sits, x,y,z in world metres (default: the world origin, the markers'); "
                  "a tracked lamp (--real-spot-tag) that the probe sees is taken out of the probe's lights there")
      ->expected(3)
      ->delimiter(',');
  add_choice_option(command, "--probe-projection", probe.projection, kProbeProjectionNames,
                    "The probe's projection: auto (lat-long when twice as wide as tall, else an equidistant fisheye "
                    "whose image circle touches the borders), fisheye, latlong");
  command.add_option("--probe-fov", probe.fov_degrees, "Fisheye probe: full field of view in degrees")
      ->capture_default_str();
  command.add_option("--probe-response", probe.response,
                     "8-bit probes: response curve file, 256 lines \"r g b\" of linear radiance (default: sRGB)");
  command
      .add_option("--probe-exposure", probe.exposure,
                  "8-bit probes: relative exposure (radiance = response / exposure)")
      ->capture_default_str();
  command
      .add_option("--probe-tolerance", probe.tolerance_s,
                  "Seconds a probe frame may be from its RGB-D frame; farther, the last probe is kept")
      ->capture_default_str();
  command
      .add_option("--probe-offset", probe.offset_s,
                  "Video probes: seconds from the first RGB-D frame to the video's first frame")
      ->capture_default_str();
  command
      .add_option("--probe-lights", probe.lights,
                  "Real lights extracted from the probe (or the estimate) every frame (default: 8; 64 with "
                  "--environment vpls)")
      ->check(CLI::Range(1, 4096));
  command.add_flag("!--no-light-smoothing", probe.smoothing,
                   "Use each frame's extracted lights as they are (no temporal smoothing, lights/light_smoothing.h)");
  command.add_option("--virtual-light", options.virtual_lights, "A virtual point light x,y,z,intensity[,r,g,b] (repeatable)");
  command.add_option("--virtual-spot", options.virtual_spots,
                     "A virtual spot light x,y,z,target_x,target_y,target_z,angle_degrees,intensity[,r,g,b] aimed at "
                     "the target, with that cone half-angle (repeatable)");
  command.add_option("--real-spot", options.real_spots,
                     "A real spot light - a lamp of the real scene - as --virtual-spot: it lights real and virtual "
                     "surfaces alike, and the virtual objects cast its shadows onto the real ones (repeatable)");
  command.add_option("--real-spot-tag", options.real_spot_tag,
                     "A tracked real lamp id,size,angle_degrees,intensity[,r,g,b]: a real spot light fixed to the "
                     "AprilTag (tag36h11) of that id and black-square edge in metres, re-posed every frame from the "
                     "tag and the camera's pose; the lamp stays where it was last seen while the tag is out of view");
  command.add_option("--real-spot-tag-offset", options.real_spot_tag_offset,
                     "Where the --real-spot-tag lamp's light sits in its tag's frame, x,y,z[,axis_x,axis_y,axis_z] "
                     "(x right, y down in the tag image, z into the tag; metres; default 0,0,0 shining along +z)");
  command.add_option("--vpls", options.vpls, "Light samples for virtual point lights per frame")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  add_choice_option(command, "--environment", options.environment, render::kEnvironmentLightNames,
                    "How the real directional lights (a probe's, an estimate's) light the scene: directional (the "
                    "direct pass, two shadow maps each) or vpls (Knecht 2010: one emitter VPL each, shadowed by its "
                    "imperfect shadow map like the other VPLs; far cheaper per light, softer shadows)");
  command
      .add_option("--merge-lights", options.merge_lights_degrees,
                  "Real directional lights (a probe's, an estimate's, a lights file's) within this many degrees of "
                  "each other light the scene as one, with their summed power: the samples a probe's brightest "
                  "source gets cast one shadow, at the cost of one light's two shadow maps; it changes the picture "
                  "slightly (0, the default: every light as extracted)")
      ->check(CLI::Range(0.0, 90.0))
      ->capture_default_str();
  add_choice_option(command, "--vpl-budget", options.vpl_budget, render::kVplBudgetNames,
                    "How the VPL samples are shared among the lights: equal, power (emitted power), weights "
                    "(--vpl-weights) or flux (the flux each light's VPLs carried last frame)");
  command
      .add_option("--vpl-weights", options.vpl_weights,
                  "With --vpl-budget weights: one weight per light, comma-separated (the real lights' order - "
                  "the lights file's, or the probe's --probe-lights - then the --virtual-light ones, the "
                  "--real-spot ones, the --virtual-spot ones; missing weights are 1)")
      ->delimiter(',')
      ->check(CLI::NonNegativeNumber);
  command.add_option("--vpl-bounces", options.vpl_bounces,
                     "Indirect bounces the VPLs carry: 1 = light reflected once, 2 adds VPLs lit by VPLs")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  command
      .add_option("--coarse-mesh-stride", options.coarse_mesh_stride,
                  "Grid stride of the reconstruction's coarse copy, which casts the real lights' shadow maps and "
                  "receives the VPLs, in pixels at 640 pixels across (scaled with the width): coarser than the "
                  "rendered mesh's (2), still about as fine as a shadow-map texel, and far cheaper to rasterise "
                  "and ray trace; 2 or less: the rendered mesh does both")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  add_choice_option(command, "--bounce-method", options.bounce_method, render::kBounceMethodNames,
                    "How bounces after the first find their surface: rays (ray traced), cone (the nearest of "
                    "the surface points within 5 degrees of the sampled direction, no ray tracing), or "
                    "previous-frame (the multiple-bounce light source: --bounce-share of the --vpls samples "
                    "continue the previous frame's VPLs, so the bounces build up over frames at a fixed cost)");
  command
      .add_option("--bounce-share", options.bounce_share,
                  "--bounce-method previous-frame: the share of the --vpls light samples that continue the "
                  "previous frame's VPLs")
      ->check(CLI::Range(0.01, 0.99))
      ->capture_default_str();
  add_choice_option(command, "--vpl-source", options.vpl_source, render::kVplSourceNames,
                    "Where a spot light's first VPLs come from: rays (traced from the light) or rsm (importance-"
                    "sampled texels of its reflective shadow maps, rasterised on the Vulkan device)");
  add_choice_option(command, "--real-albedo", options.real_albedo, kRealAlbedoNames,
                    "The k_d that real surfaces are rendered with: pixel (each camera pixel's own estimate, so "
                    "that the real-only render matches the camera's colours) or cluster (its material cluster's)");
  add_choice_option(command, "--tone-map", options.tone_map, colormap::kToneOperatorNames,
                    "How rendered light becomes the camera's range: exposure (clamp(--exposure * L, 0, 1)) or "
                    "reinhard (Reinhard's photographic operator, its key adapted to the rendered scene's average "
                    "luminance over --tone-adaptation seconds: highlights roll off instead of clipping, for cameras "
                    "that do not clip them either)");
  command
      .add_option("--exposure", options.exposure, "Tone-mapping exposure of the rendered light (--tone-map exposure)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      .add_option("--tone-key", options.tone_key,
                  "--tone-map reinhard: the key, what the scene's log-average luminance maps to (0.18: middle grey)")
      ->check(CLI::Range(0.001, 1.0))
      ->default_str("0.18");
  command
      .add_option("--tone-adaptation", options.tone_adaptation_s,
                  "--tone-map reinhard: seconds over which the key follows a change of the scene's light "
                  "(exponential time constant; 0: every frame on its own)")
      ->check(CLI::Range(0.0, 60.0))
      ->capture_default_str();
  command
      .add_option("--camera-artefacts", options.camera_artefacts,
                  "What of the camera's look goes on the virtual layer, measured in every frame: all, none, or "
                  "a comma-separated list of blur (the camera's defocus, from its edges), motion (blur along the "
                  "tracked camera motion over --exposure-time) and noise (the camera's noise per intensity)")
      ->check([](const std::string& text) {
        try {
          (void)colormap::parse_camera_artefacts(text);
          return std::string();
        } catch (const Error& error) {
          return std::string(error.what());
        }
      })
      ->capture_default_str();
  add_choice_option(command, "--composite", options.composite, render::kCompositeRuleNames,
                    "How the rendered change reaches the camera image where it sees the real scene: additive "
                    "(camera + TM(L_rv) - TM(L_r)) or multiplicative (camera * TM(L_rv) / TM(L_r): a shadow "
                    "darkens the camera's own colour even where the measured light does not reproduce it). "
                    "Default: additive; multiplicative for the main job, whose estimated light colour rests on a "
                    "white-patch guess");
  command
      .add_option("--exposure-time", options.exposure_time_s,
                  "Seconds the colour camera exposes each frame (its motion blur; at most the frame interval)")
      ->check(CLI::Range(1e-5, 10.0))
      ->default_str("0.0333");
  add_choice_option(command, "--colormap", options.colormap, colormap::kColorMapMethodNames,
                    "Map the rendered colours to the camera's: stats (CIELab statistics), sample (colour samples "
                    "and a fitted 3x4 matrix) or none; composite.mp4 shows the mapped result, frames/ both");
  add_choice_option(command, "--colormap-model", options.colormap_model, colormap::kPolynomialModelNames,
                    "Polynomial model of --colormap sample: per_channel_affine, linear_3x3 or affine_3x4");
  command.add_flag("--channel-swap", options.channel_swap,
                   "--colormap sample: also fit channel-permuted colour pairs (helps when the virtual colour is "
                   "absent from the real scene and the camera treats R, G, B alike)");
  command.add_flag("--buffers", options.write_buffers,
                   "Also write L_rv, L_r and (with colour mapping) delta_L per frame as EXR under frames/");
  command.add_flag("!--no-video", options.video, "Do not write composite.mp4");
}

void add_frame_options(CLI::App& command, ReplayOptions& options) {
  command.add_flag("!--no-frames", options.write_frames, "Do not write per-frame images");
  add_choice_option(command, "--previews", options.previews, kPreviewFramesNames,
                    "Frames whose inner buffers (depth, smoothed depth, normals, the BRDF estimation's mosaic, and "
                    "the composite before colour mapping when there is a mapped one) are made and written as "
                    "pictures: shown (the frames report.html shows) or every frame; the camera image and the final "
                    "composite are written for every frame");
}

void add_view_options(CLI::App& command, ReplayOptions& options) {
  command.add_flag("--view", options.view,
                   "Show the final picture in a window as it is made, with fps, tracking state and dropped frames; "
                   "keys: q quit, space pause, s snapshot (to DIR/snapshots/)");
  add_choice_option(command, "--view-side", options.view_side, kViewSides,
                    "With --view: a buffer shown beside the picture");
}

namespace {

struct Registry {
  Runners runners;
};

Registry& registry() {
  static Registry instance;
  return instance;
}

void add_no_object_option(CLI::App& command, ReplayOptions& options) {
  command.add_flag("--no-object", options.no_object,
                   "On the embedded sample without --object: geometry only (by default the shipped pebble is "
                   "rendered on the sample's table, lit by the shipped light probe)");
}

void register_replay(CLI::App& app) {
  auto options = std::make_shared<ReplayOptions>();
  CLI::App* replay = app.add_subcommand("replay", "Run the pipeline on a recorded RGB-D sequence (TUM folder or .oni)");
  replay->add_option("sequence", options->sequence, "TUM RGB-D folder or OpenNI2 .oni recording (default: the embedded sample)");
  replay->add_option("--out", options->out, "Output folder")->capture_default_str();
  replay->add_option("--frames", options->frames, "Frame range A:B (B exclusive), A:, :B or N");
  replay->add_option("--loop", options->loops, "Play the sequence (after --frames) this many times, e.g. for soak runs")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  add_choice_option(*replay, "--intrinsics", options->intrinsics, kIntrinsicsPresets,
                    "Override the sequence's intrinsics: the Kinect v1 defaults or a TUM calibration");
  replay->add_flag("--quiet", options->quiet, "No progress or summary on stderr");
  add_frame_options(*replay, *options);
  replay->add_flag("--skip-bad-frames", options->skip_bad_frames,
                   "A TUM frame that cannot be read is skipped with a warning naming it (default: an error)");
  add_pose_options(*replay, *options);
  add_compute_options(*replay, *options);
  add_render_options(*replay, *options);
  add_view_options(*replay, *options);
  add_no_object_option(*replay, *options);
  registry().runners[replay] = [options] { return run_replay(*options); };
}

void register_graph(CLI::App& app) {
  auto dot = std::make_shared<bool>(false);
  CLI::App* graph = app.add_subcommand("graph", "Show the replay frame graph (stages, buffers, order)");
  graph->add_flag("--dot", *dot, "Print Graphviz DOT instead of the execution order");
  auto options = std::make_shared<ReplayOptions>();
  add_pose_options(*graph, *options);
  add_compute_options(*graph, *options);
  add_render_options(*graph, *options);  // the graph for any content: --object, --colormap, ...
  add_no_object_option(*graph, *options);
  registry().runners[graph] = [dot, options] {
    ReplayPipeline pipeline = build_replay_pipeline(open_replay_source(*options), *options);
    FrameGraph& frame_graph = *pipeline.graph;
    frame_graph.compile();
    if (*dot) {
      std::cout << frame_graph.to_dot();
    } else {
      for (const auto& stage : frame_graph.execution_order()) std::cout << stage << "\n";
    }
    return 0;
  };
}

}  // namespace

void register_commands(CLI::App& app) {
  add_json_config(app);
  // Settings made before add_subcommand are inherited by the subcommands.
  app.allow_config_extras(CLI::config_extras_mode::error);  // a misspelt key is an error, not ignored
  app.fallthrough();  // so that `relight replay --config cfg.json` reaches the main app's --config
  register_replay(app);
  register_graph(app);
  register_synth(app, registry().runners);
  register_lights(app, registry().runners);
  register_render(app, registry().runners);
  register_live(app, registry().runners);
}

int run_selected(CLI::App& app) {
  for (CLI::App* command : app.get_subcommands()) {
    const auto runner = registry().runners.find(command);
    if (runner != registry().runners.end()) return runner->second();
  }
  std::cerr << app.help();
  return 2;
}

}  // namespace relight::app
