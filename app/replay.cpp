#include "replay.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <optional>

#include "as_rendered_composite_stage.h"
#include "camera_trajectory_stage.h"
#include "constant_stage.h"
#include "device_loss.h"
#include "device_memory_watch.h"
#include "frame_range.h"
#include "frame_writer_stage.h"
#include "interrupt.h"
#include "latency_stage.h"
#include "live_view.h"
#include "marker_trajectory_stage.h"
#include "mixed_reality_scene.h"
#include "object_placement_stage.h"
#include "relight/brdf/brdf_preview.h"
#include "relight/brdf/brdf_stages.h"
#include "relight/brdf/buffers.h"
#include "relight/capture/buffers.h"
#include "relight/capture/camera_tracking_stage.h"
#include "relight/capture/looping_source.h"
#include "relight/capture/marker_pose.h"
#include "relight/capture/openni_source.h"
#include "relight/capture/prefetch_source.h"
#include "relight/capture/range_source.h"
#include "relight/capture/source_stage.h"
#include "relight/capture/tag_detection_stage.h"
#include "relight/capture/tum_sequence.h"
#include "relight/colormap/colormap_stages.h"
#include "relight/colormap/tone_map_stage.h"
#include "relight/core/atomic_file.h"
#include "relight/core/buffers.h"
#include "relight/core/error.h"
#include "relight/core/progress.h"
#include "relight/lights/buffers.h"
#include "relight/reconstruct/depth_box_filter.h"
#include "relight/reconstruct/depth_warp_merge.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"
#include "relight/render/buffers.h"
#include "relight/render/dir/dir_stage.h"
#include "relight/render/dir/mapped_composite_stage.h"
#include "relight/render/scene/model_io.h"
#include "relight/render/scene/scene_lights.h"
#include "relight/vk/backend.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"
#include "report.h"
#include "report_collector_stage.h"
#include "tone_map_json.h"
#include "tracked_lamp_stage.h"
#include "video_writer_stage.h"
#include "view_stage.h"

namespace relight::app {

std::filesystem::path data_folder() {
  if (const char* env = std::getenv("RELIGHT_DATA"); env && *env) return env;
  return RELIGHT_DATA_DIR;
}

std::filesystem::path default_sequence() { return data_folder() / "tum_fr1_rpy"; }

namespace {

std::unique_ptr<capture::FrameSource> open_source_once(const ReplayOptions& options) {
  capture::TumOptions tum;
  tum.intrinsics = options.intrinsics;
  const FrameRange range = options.frames.empty() ? FrameRange{} : parse_frame_range(options.frames);
  const auto folder = options.sequence.empty() ? default_sequence() : options.sequence;
  if (folder.extension() == ".oni") {  // OpenNI2 recording, played back through its file device
    capture::OpenNiOptions oni;
    oni.uri = folder.string();
    oni.intrinsics = tum.intrinsics;
    return std::make_unique<capture::RangeSource>(std::make_unique<capture::OpenNiSource>(oni), range.first,
                                                  range.last);
  }
  auto source = std::make_unique<capture::TumSource>(capture::TumSequence::open(folder, tum), range.first, range.last);
  if (options.skip_bad_frames) {
    source->on_bad_frame([](std::size_t index, const std::string& message) {
      std::cerr << "relight: warning: frame " << index << " skipped: " << message << "\n";
    });
  }
  return source;
}

}  // namespace

std::unique_ptr<capture::FrameSource> open_replay_source(const ReplayOptions& options) {
  if (options.loops < 1) throw Error("--loop must be at least 1");
  std::unique_ptr<capture::FrameSource> source =
      options.loops == 1
          ? open_source_once(options)
          : std::make_unique<capture::LoopingSource>([options] { return open_source_once(options); }, options.loops);
  // A TUM folder's next frame is decoded on a worker thread while this one is processed
  // (prefetch_source.h); an .oni recording plays through OpenNI's own reader thread.
  if (options.sequence.extension() == ".oni") return source;
  return std::make_unique<capture::PrefetchSource>(std::move(source));
}

ReplayPipeline::ReplayPipeline() = default;
ReplayPipeline::~ReplayPipeline() = default;
ReplayPipeline::ReplayPipeline(ReplayPipeline&&) noexcept = default;

namespace {

// No Vulkan context is made when everything runs on the CPU anyway (--backend cpu).
std::unique_ptr<vk::VulkanContext> make_vulkan(const ReplayOptions& options, vk::BackendPolicy policy) {
  if (policy == vk::BackendPolicy::ForceCpu) return nullptr;
  vk::VulkanOptions vulkan_options;
  vulkan_options.device = options.device;
  return vk::try_create_vulkan(vulkan_options);
}

// The folder that may describe the scene (scene.json, probe.hdr): the sequence's, or a live
// device's when it serves one (relight's own driver); none for other live devices.
std::optional<std::filesystem::path> scene_folder(const ReplayOptions& options) {
  if (!options.live_device.empty()) {
    if (options.device_scene.empty()) return std::nullopt;
    return options.device_scene;
  }
  return options.sequence.empty() ? default_sequence() : options.sequence;
}

// "auto" uses the scene's scene.json when it describes a tag (sequences from `relight synth`).
std::optional<capture::TagLayout> marker_layout(const ReplayOptions& options) {
  if (options.markers == "none") return std::nullopt;
  if (options.markers != "auto") return capture::read_tag_layout(options.markers);
  const auto folder = scene_folder(options);
  if (!folder) return std::nullopt;
  const auto scene = *folder / "scene.json";
  if (!std::filesystem::exists(scene)) return std::nullopt;
  const std::string text = read_text_file(scene);
  if (text.find("\"tag\"") == std::string::npos) return std::nullopt;
  return capture::parse_tag_layout(text, scene.string());
}

/// The colour mapping between DIR's L_rv/L_r and the camera, and its composite; returns the
/// buffer that holds the final picture (DIR's own composite when there is no mapping).
BufferName<ColorImage> add_color_mapping(ReplayPipeline& pipeline, const ReplayOptions& options, Backend per_pixel,
                                         bool camera_look) {
  const auto method = options.colormap;
  if (method == colormap::ColorMapMethod::None) return kComposite;  // DIR's own composite is unmapped
  colormap::SampleMappingOptions mapping;
  mapping.channel_swap = options.channel_swap;
  mapping.model = options.colormap_model;
  colormap::ColorMapBuffers buffers;
  buffers.tone_map = colormap::kToneMap;  // the tone_map stage's, every frame
  pipeline.graph->add(colormap::make_color_map_stage(method, per_pixel, pipeline.vulkan.get(), mapping, buffers));
  pipeline.graph->emplace<render::MappedCompositeStage>(camera_look, pipeline.composite_rule);
  pipeline.graph->keep(kCompositeMapped);
  return kCompositeMapped;
}

/// The lights, the BRDF stages (real materials) and the DIR stage with its outputs, when the
/// options ask for any virtual content.
/// `shown`: the frames report.html shows.
void add_differential_rendering(ReplayPipeline& pipeline, const ReplayOptions& options, Backend per_pixel,
                                const FrameFilter& shown) {
  check_real_places(options.real_objects, options.real_places);
  if (options.objects.empty() && options.virtual_lights.empty() && options.virtual_spots.empty()) {
    if (!options.real_objects.empty())
      throw Error("--real-object needs something virtual to render (--object, --virtual-light or --virtual-spot)");
    return;
  }
  if (options.vpls < 0 || options.vpls > 4096) throw Error("--vpls must be 0 to 4096");
  if (!(options.exposure > 0.f)) throw Error("--exposure must be positive");
  const auto scene = scene_folder(options);
  const bool synthetic = scene && scene->extension() != ".oni" && is_synthetic(*scene);
  const RealLightSource real_lights =
      real_light_source(options.lights, options.probe, scene,
                        options.live_device.empty() ? scene.value_or("").string() + " has no light probe"
                                                    : "the device " + options.live_device + " serves no light probe");
  render::DirSceneContent content;  // the real lights come per frame from lights::kLights
  for (const std::string& light : options.virtual_lights) content.lights.push_back(parse_virtual_light(light));
  for (const std::string& spot : options.real_spots) content.lights.push_back(parse_spot("--real-spot", spot, true));
  for (const std::string& spot : options.virtual_spots) content.lights.push_back(parse_virtual_spot(spot));
  auto requests = placement_requests(options.objects.size(), options.places, options.places_at,
                                     options.places_on_plane, kDefaultSynthPlacement, synthetic);
  std::vector<std::string> names;
  for (std::size_t i = 0; i < options.objects.size(); ++i) {
    render::VirtualModel model = load_model_telling_warnings(options.objects[i]);
    const Eigen::AlignedBox3f box = render::bounds(model);  // y-up: the footprint is x by z
    requests[i].footprint_radius_m =
        requests[i].placement.scale * 0.5 * std::hypot(box.sizes().x(), box.sizes().z());
    content.objects.emplace_back(std::move(model), requests[i].placement);
    names.push_back(options.objects[i].filename().string());
  }

  content.real_objects = load_real_objects(options.real_objects, options.real_places);

  FrameGraph& graph = *pipeline.graph;
  if (!content.objects.empty())
    pipeline.placement = &graph.emplace<ObjectPlacementStage>(std::move(requests), std::move(names));
  const bool lights_as_vpls = options.environment == render::EnvironmentLight::Vpls;
  ProbeInputOptions probe_input = options.probe_input;
  if (probe_input.lights == 0) probe_input.lights = lights_as_vpls ? 64 : 8;
  // A tracked lamp joins the room's lights after their smoothing: it moves by hand, at once.
  const bool lamp = !options.real_spot_tag.empty();
  if (!lamp && !options.real_spot_tag_offset.empty()) throw Error("--real-spot-tag-offset needs --real-spot-tag");
  const RealLightStages light_stages = add_real_light_stages(
      graph, real_lights, probe_input, per_pixel, pipeline.vulkan.get(), lamp ? kRoomLights : lights::kLights);
  if (lamp) {
    // A probe the lamp shines on holds it too; the lamp stage takes it out there.
    const bool from_probe = real_lights.lights_file.empty() && !real_lights.estimate;
    pipeline.tracked_lamp = &graph.emplace<TrackedLampStage>(
        parse_tracked_lamp(options.real_spot_tag, options.real_spot_tag_offset),
        from_probe ? std::optional<Eigen::Vector3d>(probe_position(probe_input)) : std::nullopt);
  }
  pipeline.probe = light_stages.probe;
  if (real_lights.lights_file.empty()) pipeline.extracted_lights = probe_input.lights;
  pipeline.light_estimation = light_stages.estimation;
  pipeline.lights_estimated_because = real_lights.fallback;
  if (!real_lights.fallback.empty() && !options.quiet)
    std::cerr << "relight: " << real_lights.fallback
              << ": the real lights are estimated from the frames (--lights estimate; --probe or --lights FILE to "
                 "give them)\n";
  brdf::add_brdf_stages(graph, {}, per_pixel, pipeline.vulkan.get());
  // Culled unless the frame writer or report.html shows it; with the report alone only for its
  // contact-sheet frames (build_replay_pipeline).
  pipeline.brdf_preview = &graph.emplace<brdf::BrdfPreviewStage>();
  render::DirStageOptions dir;
  dir.vpls.count = options.vpls;
  dir.vpls.budget = options.vpl_budget;
  dir.vpls.light_weights = options.vpl_weights;
  dir.vpls.bounces = options.vpl_bounces;
  dir.vpls.bounce_method = options.bounce_method;
  dir.vpls.bounce_share = options.bounce_share;
  dir.vpls.source = options.vpl_source;
  dir.coarse_mesh_stride = options.coarse_mesh_stride;
  dir.tone_map = {.op = options.tone_map,
                  .exposure = options.exposure,
                  .key = options.tone_key,
                  .adaptation_s = options.tone_adaptation_s};
  render::CameraLookOptions look;
  look.artefacts = colormap::parse_camera_artefacts(options.camera_artefacts);
  look.exposure_time_s = options.exposure_time_s;
  dir.camera_look = look;
  // Where a colour-mapped composite is the final picture, the plain one is an intermediate like
  // the other previews (--previews): the report's frames only, unless the live view shows it.
  const bool view_shows_plain = options.view && options.view_side == PreviewBuffer{kComposite};
  if (options.colormap != colormap::ColorMapMethod::None && options.previews == PreviewFrames::Shown &&
      !view_shows_plain)
    dir.composite_frames = shown;
  dir.composite = options.composite.value_or(render::CompositeRule::Additive);
  pipeline.composite_rule = dir.composite;
  dir.environment = options.environment;
  dir.merge_lights_degrees = options.merge_lights_degrees;
  dir.materials_buffer = brdf::kMaterials;
  dir.real_lights_buffer = lights::kLights;
  if (pipeline.placement) dir.placements_buffer = render::kObjectPlacements;
  if (options.real_albedo == RealAlbedo::Pixel) dir.albedo_buffers = render::RealAlbedoBuffers{};
  // The measured lights are several soft directional lights (8 from a probe): 256 texels per view
  // keep their shadows, at a quarter of the rasterisation and memory of 512.
  dir.renderer.shadow_tile = 256;
  // DIR rasterises: on Vulkan wherever a device exists, lavapipe included (vk::StageKind).
  const Backend rendering = vk::choose_backend(vk::StageKind::Rasterisation, pipeline.vulkan.get(), options.backend);
  const render::DirStages stages =
      render::add_dir_stages(graph, rendering, pipeline.vulkan.get(), std::move(content), dir);
  pipeline.camera_look = stages.camera_look;
  pipeline.tone_map = stages.tone_map;
  pipeline.vpls = stages.vpls;
  pipeline.dir = stages.dir;
  graph.keep(kComposite);
  pipeline.final_composite = add_color_mapping(pipeline, options, per_pixel, look.artefacts.any());
  if (options.video) graph.emplace<VideoWriterStage>(options.out / "composite.mp4", pipeline.final_composite);
  pipeline.renders = true;
}

// How warnings name the AprilTag layout in use.
std::string marker_layout_name(const ReplayOptions& options) {
  if (options.markers != "auto") return options.markers;
  const auto folder = scene_folder(options);
  return folder ? (*folder / "scene.json").string() : "the device's scene";
}

/// The marker pose (when there is a layout) and the camera tracking stage that turns the
/// source's frame into the tracked "frame" every pose reader uses.
void add_camera_pose(ReplayPipeline& pipeline, const ReplayOptions& options) {
  capture::CameraTrackingOptions tracking;
  tracking.source = options.pose;
  auto layout = marker_layout(options);
  tracking.has_marker_layout = layout.has_value();
  // The tags of each frame for the marker pose and a tracked lamp alike (culled when neither runs).
  pipeline.graph->emplace<capture::TagDetectionStage>();
  if (layout) {
    pipeline.graph->emplace<capture::MarkerPoseStage>(std::move(*layout), kSourceFrame);
    pipeline.markers =
        &pipeline.graph->emplace<MarkerTrajectoryStage>(options.out / "marker_trajectory.txt", marker_layout_name(options));
  }
  pipeline.graph->emplace<capture::CameraTrackingStage>(tracking);
  pipeline.trajectory = &pipeline.graph->emplace<CameraTrajectoryStage>(options.out / "camera_trajectory.txt");
}

/// --view: the window (opened now, so that a missing display fails before any frame) and the
/// stage that feeds it the final picture.
void add_view(ReplayPipeline& pipeline, const ReplayOptions& options, bool method2) {
  const std::optional<PreviewBuffer>& side = options.view_side;
  const bool needs_render = side == PreviewBuffer{kComposite} || side == PreviewBuffer{render::kVirtualCoverage};
  if (needs_render && !pipeline.renders) {
    throw Error(std::string("--view-side ") + name_of(kViewSides, *side) + " needs something to render (--object)");
  }
  if (side == PreviewBuffer{kDepthFiltered} && !method2) {
    throw Error("--view-side depth_filtered needs --geometry method2");
  }
  pipeline.view = std::make_unique<LiveView>(
      "relight " + (options.live_device.empty() ? std::string("replay") : "live: " + options.live_device),
      options.out / "snapshots");
  pipeline.view_stage =
      &pipeline.graph->emplace<ViewStage>(*pipeline.view, pipeline.renders ? pipeline.final_composite : kColor, side);
}

void add_report_collector(ReplayPipeline& pipeline, std::int64_t total_frames, bool method2) {
  auto collector = std::make_unique<ReportCollectorStage>(total_frames);
  collector->add_picture(kColor);
  collector->add_picture(method2 ? kDepthFiltered : kDepthSmoothed);
  collector->add_picture(kNormals);
  if (pipeline.renders) {
    if (pipeline.camera_look) {
      // Before and after the camera's look, side by side: the virtual layer as rendered (sharp,
      // noiseless), then as this camera would have filmed it.
      const ReportCollectorStage* shown = collector.get();
      pipeline.graph->emplace<AsRenderedCompositeStage>(pipeline.composite_rule,
                                                        [shown](std::int64_t frame) { return shown->shows(frame); });
      collector->add_close_up(kCompositeAsRendered, kComposite, render::kVirtualCoverage);
    }
    collector->add_picture(kComposite);
    if (pipeline.final_composite != kComposite) collector->add_picture(pipeline.final_composite);
    collector->add_picture(kBrdfPreview);  // a wide mosaic: last, so it wraps alone
    collector->collect_materials(brdf::kMaterials);
    collector->collect_lights(lights::kLights);
  }
  pipeline.report = collector.get();
  pipeline.graph->add(std::move(collector));
}

nlohmann::ordered_json camera_look_json(const render::CameraLookSummary& summary) {
  nlohmann::ordered_json noise = nlohmann::ordered_json::array();
  for (int band = 0; band < colormap::kNoiseBands; ++band) {
    const auto& sigma = summary.noise.sigma[static_cast<std::size_t>(band)];
    noise.push_back({{"code", (band + 0.5) * 256.0 / colormap::kNoiseBands},
                     {"sigma", {sigma[0], sigma[1], sigma[2]}},
                     {"samples", summary.noise.samples[static_cast<std::size_t>(band)]}});
  }
  return {{"artefacts", colormap::to_string(summary.artefacts)},
          {"frames", summary.frames},
          {"blur_sigma_px", summary.blur_sigma_px},
          {"applied_blur_sigma_px", summary.applied_sigma_px},
          {"blur_edges", summary.blur_edges},
          {"blur_estimates", summary.blur_estimates},
          {"noise_estimates", summary.noise_estimates},
          {"frames_with_motion", summary.frames_with_motion},
          {"max_motion_px", summary.max_motion_px},
          {"noise", std::move(noise)}};
}

// The VPLs of the run: options and mean counts per frame by bounce.
nlohmann::ordered_json vpl_json(const render::VplStage& stage) {
  const render::VplOptions& options = stage.options();
  const render::VplStage::Summary summary = stage.summary();
  nlohmann::ordered_json per_bounce = nlohmann::ordered_json::object();
  for (std::size_t bounce = 0; bounce < summary.mean_by_bounce.size(); ++bounce) {
    if (summary.mean_by_bounce[bounce] <= 0.0) continue;
    per_bounce[bounce == 0 ? std::string("emitters") : "bounce_" + std::to_string(bounce)] =
        summary.mean_by_bounce[bounce];
  }
  nlohmann::ordered_json json{{"light_samples", options.count},
                              {"bounces", options.bounces},
                              {"bounce_method", name_of(render::kBounceMethodNames, options.bounce_method)},
                              {"source", name_of(render::kVplSourceNames, options.source)},
                              {"mean_per_frame", std::move(per_bounce)},
                              {"first_frame_later_bounces", summary.first_frame_later_bounces}};
  if (options.bounce_method == render::BounceMethod::PreviousFrame) json["bounce_share"] = options.bounce_share;
  return json;
}

}  // namespace

std::optional<nlohmann::ordered_json> dir_steps_json(const render::DirRenderStage& stage) {
  const std::vector<render::DirVkTimings>& frames = stage.step_timings();
  if (frames.empty()) return std::nullopt;
  // The same median as the stages' beside them in report.json (summarize).
  const auto median = [&](double render::DirVkTimings::*step) {
    std::vector<double> values;
    values.reserve(frames.size());
    for (const render::DirVkTimings& t : frames) values.push_back(t.*step);
    return summarize(std::move(values)).median;
  };
  nlohmann::ordered_json steps{{"gbuffer", median(&render::DirVkTimings::gbuffer_ms)},
                               {"shadow_maps", median(&render::DirVkTimings::shadow_maps_ms)},
                               {"ism", median(&render::DirVkTimings::ism_ms)},
                               {"shading", median(&render::DirVkTimings::shading_ms)}};
  if (!frames.back().cpu_shading) steps["merge"] = median(&render::DirVkTimings::merge_ms);
  if (frames.back().specular_ms > 0.0) steps["specular"] = median(&render::DirVkTimings::specular_ms);
  return nlohmann::ordered_json{{"frames", frames.size()},
                                {"shading_on", frames.back().cpu_shading ? "cpu" : "device"},
                                {"median_ms", std::move(steps)}};
}

void add_pipeline_summaries(nlohmann::ordered_json& report, const ReplayPipeline& pipeline,
                            const ReplayOptions& options) {
  if (pipeline.view) report["view"] = {{"drawn", pipeline.view->drawn()}, {"skipped", pipeline.view->skipped()}};
  if (pipeline.markers) {
    report["marker_pose"] = pipeline.markers->summary();
    std::cerr << pipeline.markers->no_tag_warning(marker_layout_name(options));
  }
  report["tracking"] = pipeline.trajectory->summary();
  if (pipeline.probe) report["probe"] = pipeline.probe->summary();
  if (pipeline.light_estimation) {
    report["light_estimate"] = pipeline.light_estimation->summary();
    report["light_estimate"]["chosen"] =
        pipeline.lights_estimated_because.empty() ? "--lights estimate" : pipeline.lights_estimated_because;
  }
  if (pipeline.tracked_lamp) {
    report["tracked_lamp"] = pipeline.tracked_lamp->summary();
    if (pipeline.tracked_lamp->frames_seen() == 0) {
      std::cerr << "relight: warning: the lamp's tag (tag36h11 id " << report["tracked_lamp"]["tag_id"].get<int>()
                << ") was in no frame: the lamp did not light the scene\n";
    }
  }
  if (pipeline.renders) {
    report["environment"] = {{"mode", name_of(render::kEnvironmentLightNames, options.environment)},
                             {"extracted_lights", pipeline.extracted_lights},
                             {"merge_lights_degrees", options.merge_lights_degrees}};
    report["composite"] = {{"rule", name_of(render::kCompositeRuleNames, pipeline.composite_rule)}};
  }
  if (pipeline.vpls) report["vpls"] = vpl_json(*pipeline.vpls);
  if (pipeline.dir) {
    if (auto steps = dir_steps_json(*pipeline.dir)) report["dir_steps"] = std::move(*steps);
  }
  if (pipeline.camera_look) report["camera_look"] = camera_look_json(pipeline.camera_look->summary());
  if (pipeline.tone_map) report["tone_map"] = tone_map_json(pipeline.tone_map->options(), pipeline.tone_map->last());
  report["latency_ms"] = pipeline.latency->summary();
  if (!options.real_objects.empty())
    report["real_objects"] = real_objects_json(options.real_objects, options.real_places);
  if (pipeline.placement) {
    report["placements"] = pipeline.placement->summary();
    if (!options.quiet) std::cerr << pipeline.placement->describe();
  }
}

ReplayOptions with_main_job_defaults(ReplayOptions options) {
  const bool embedded_sample = options.sequence.empty() && options.live_device.empty();
  const bool nothing_to_render =
      options.objects.empty() && options.virtual_lights.empty() && options.virtual_spots.empty();
  if (!embedded_sample || !nothing_to_render || options.no_object) return options;
  options.objects = {data_folder() / "models" / "glossy_pebble.gltf"};
  options.places_on_plane = {""};
  // The sample was recorded without a light probe: its light is estimated from its frames
  // (real_light_source()'s fallback, which says so on stderr and in report.json).
  if (options.lights.empty() && options.probe.empty()) {
    // The estimate's light colour rests on the white-patch assumption (brdf/light_estimation.h:
    // 0.13 off in chromaticity on the synthetic room): an additive shadow subtracts that tint
    // and leaves its complement around the pebble; the ratio darkens the desk's own colour.
    if (!options.composite) options.composite = render::CompositeRule::Multiplicative;
  }
  return options;
}

ReplayPipeline build_replay_pipeline(std::unique_ptr<capture::FrameSource> source, const ReplayOptions& given) {
  const ReplayOptions options = with_main_job_defaults(given);
  const vk::BackendPolicy policy = options.backend;
  ReplayPipeline pipeline;
  pipeline.vulkan = make_vulkan(options, policy);
  pipeline.graph = std::make_unique<FrameGraph>(pipeline.vulkan ? &pipeline.vulkan->transfer() : nullptr);
  const Backend per_pixel = vk::choose_backend(vk::StageKind::PerPixel, pipeline.vulkan.get(), policy);
  pipeline.compute = std::string("per-pixel stages on ") + to_string(per_pixel) +
                     (pipeline.vulkan ? " (Vulkan device: " + pipeline.vulkan->device_info().name + ")"
                                      : " (no Vulkan device in use)");

  FrameGraph& graph = *pipeline.graph;
  const std::int64_t total_frames = source->size_hint();
  graph.emplace<capture::SourceStage>(std::move(source), kSourceFrame);
  graph.add(reconstruct::make_depth_box_filter_stage(per_pixel, pipeline.vulkan.get()));
  // Geometry (positions + normals) follows the per-pixel backend; method 1's
  // pass-1 pyramid stays on the CPU either way (normals_raw_depth_vk.h).
  const bool method2 = options.geometry == GeometryMethod::Method2;
  if (method2) graph.add(reconstruct::make_depth_warp_merge_stage(per_pixel, pipeline.vulkan.get()));
  const auto input = method2 ? reconstruct::NormalsDepthInput::Filtered : reconstruct::NormalsDepthInput::Raw;
  if (method2 && options.method2_normals == Method2Normals::Plain) {
    graph.add(reconstruct::make_normals_from_positions_stage(per_pixel, pipeline.vulkan.get()));
  } else {
    graph.add(reconstruct::make_normals_raw_depth_stage(per_pixel, pipeline.vulkan.get(),
                                                        reconstruct::NormalsRawDepthOptions{}, input));
  }
  graph.keep(kNormals);
  graph.keep(kPositions);
  add_camera_pose(pipeline, options);
  // The frames report.html shows: the inner buffers' pictures by default (--previews).
  const FrameFilter shown = [total_frames](std::int64_t frame) {
    return contact_sheet_row(frame, total_frames, kContactSheetRows).has_value();
  };
  add_differential_rendering(pipeline, options, per_pixel, shown);
  pipeline.latency =
      &graph.emplace<LatencyStage>(pipeline.renders ? std::optional(pipeline.final_composite) : std::nullopt);
  if (options.view) add_view(pipeline, options, method2);
  const bool every_preview = options.write_frames && options.previews == PreviewFrames::Every;
  const FrameFilter previewed = every_preview ? FrameFilter{} : shown;
  if (options.write_frames) {
    auto writer = std::make_unique<FrameWriterStage>(options.out / "frames");
    writer->add(kColor);
    writer->add(kDepth, previewed);
    writer->add(kDepthSmoothed, previewed);
    if (method2) writer->add(kDepthFiltered, previewed);
    writer->add(kNormals, previewed);
    if (pipeline.renders) {
      if (pipeline.final_composite != kComposite) {
        writer->add(kComposite, previewed);  // an intermediate then (add_differential_rendering)
        writer->add(pipeline.final_composite);
      } else {
        writer->add(kComposite);
      }
      writer->add(kBrdfPreview, previewed);
    }
    if (pipeline.renders && options.write_buffers) {
      writer->add(kRealVirtualRadiance);
      writer->add(kRealRadiance);
      writer->add(render::kVirtualCoverage);
      if (pipeline.final_composite != kComposite) writer->add(kDeltaRadiance);  // the colour-mapped difference
    }
    graph.add(std::move(writer));
  }
  add_report_collector(pipeline, total_frames, method2);
  // The mosaic's re-render costs as much as the BRDF estimation's own stages: made only for the
  // frames that write or show it.
  if (pipeline.brdf_preview && !every_preview) pipeline.brdf_preview->only_for(shown);
  return pipeline;
}

int run_replay(const ReplayOptions& options) {
  // Ctrl-C stops after the current frame; the outputs are then finalised as at the end.
  InterruptGuard interrupt;
  auto source = open_replay_source(options);
  const std::string description = source->describe();
  const std::int64_t total = source->size_hint();
  std::error_code ec;
  std::filesystem::create_directories(options.out, ec);
  if (ec) throw Error("cannot create output folder " + options.out.string() + ": " + ec.message());

  ReplayPipeline pipeline = build_replay_pipeline(std::move(source), options);
  FrameGraph& graph = *pipeline.graph;
  graph.compile();
  write_file_atomically(options.out / "graph.dot", graph.to_dot());
  if (!options.quiet) std::cerr << "relight replay: " << description << "; " << pipeline.compute << "\n";

  ProgressBar progress("replay", total, options.quiet);
  const auto start = std::chrono::steady_clock::now();
  const auto view_quit = [&pipeline] { return pipeline.view && pipeline.view->quit_requested(); };
  DeviceMemoryWatch device_memory(pipeline.vulkan.get());
  DeviceLossHook device_loss(pipeline.vulkan.get());
  std::optional<std::string> failure;  // a lost Vulkan device: finalised like an end, then an error
  try {
    while (!InterruptGuard::interrupted() && !view_quit()) {
      device_loss.before_frame(graph.frames_run());
      if (!graph.run_frame()) break;
      progress.update(graph.frames_run());
      device_memory.after_frame(graph.frames_run());
    }
  } catch (const Error& e) {
    failure = device_loss_message(e, graph.frames_run());
    if (!failure) throw;
  }
  progress.finish();
  graph.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool interrupted = InterruptGuard::interrupted();
  const bool quit_from_view = !interrupted && view_quit();

  auto report = timing_report(graph, seconds);
  report["sequence"] = description;
  report["compute"] = pipeline.compute;
  report["stopped_by"] = failure ? "error: " + *failure : interrupted ? "interrupt" : quit_from_view ? "view" : "end";
  device_memory.add_to(report, graph.frames_run());
  add_pipeline_summaries(report, pipeline, options);
  write_reports(options.out, "relight replay: " + description, graph, report, pipeline.report);
  if (failure) throw Error(*failure);
  if (interrupted) {
    // Not a failure of the input, but the run did not cover it: 128 + SIGINT, as shells report it.
    std::cerr << "relight: warning: replay interrupted after " << graph.frames_run() << " of " << total
              << " frames; the outputs in " << options.out.string() << " are complete for those frames\n";
    return 130;
  }
  if (!options.quiet) {
    std::cerr << "relight replay: " << graph.frames_run() << " frames in " << seconds << " s"
              << (quit_from_view ? " (stopped from the view)" : "") << "; results in "
              << options.out.string() << " (report.html, report.json, graph.dot, camera_trajectory.txt, frames/"
              << (pipeline.renders && options.video ? ", composite.mp4" : "") << ")\n";
  }
  return 0;
}

}  // namespace relight::app
