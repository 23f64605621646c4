#pragma once
// `relight replay`: runs the frame graph over a recorded sequence and writes the results.
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "buffer_previews.h"
#include "probe_input.h"
#include "relight/capture/camera_pose.h"
#include "relight/capture/frame_source.h"
#include "relight/colormap/colormap_stages.h"
#include "relight/colormap/sample_mapping.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/named_values.h"
#include "relight/render/dir/dir_stage.h"
#include "relight/render/vpl/vpl.h"
#include "relight/vk/backend.h"

namespace relight::brdf {
class BrdfPreviewStage;
}

namespace relight::app {

class CameraTrajectoryStage;
class LatencyStage;
class MarkerTrajectoryStage;
class LiveView;
class ObjectPlacementStage;
class ViewStage;
class ReportCollectorStage;
class TrackedLampStage;

/// --geometry: method 1 (NormalsRawDepth on the raw depth) or method 2 (DepthWarpMerge, then
/// the normals of `Method2Normals`).
enum class GeometryMethod { Method1, Method2 };
inline constexpr std::array<NamedValue<GeometryMethod>, 2> kGeometryMethodNames{
    {{"method1", GeometryMethod::Method1}, {"method2", GeometryMethod::Method2}}};
/// Method 2's normals: method 1's estimator on the merged depth (§4.3.3's filtered normal), or
/// stride-1 cross products of the merged positions (NormalsFromPositions).
enum class Method2Normals { Filtered, Plain };
inline constexpr std::array<NamedValue<Method2Normals>, 2> kMethod2NormalsNames{
    {{"filtered", Method2Normals::Filtered}, {"plain", Method2Normals::Plain}}};
/// Which frames get the per-frame pictures of the pipeline's inner buffers (depth, smoothed and
/// filtered depth, normals, the BRDF estimation's mosaic, and the composite before colour mapping
/// when a colour-mapped one is the final picture): the frames report.html shows, or every frame.
/// The camera image and the final composite are written for every frame either way.
enum class PreviewFrames { Shown, Every };
inline constexpr std::array<NamedValue<PreviewFrames>, 2> kPreviewFramesNames{
    {{"shown", PreviewFrames::Shown}, {"every", PreviewFrames::Every}}};

/// The k_d real surfaces are rendered with: each camera pixel's own estimate (render/dir/camera_albedo.h)
/// or its material cluster's.
enum class RealAlbedo { Pixel, Cluster };
inline constexpr std::array<NamedValue<RealAlbedo>, 2> kRealAlbedoNames{
    {{"pixel", RealAlbedo::Pixel}, {"cluster", RealAlbedo::Cluster}}};

struct ReplayOptions {
  std::filesystem::path sequence;  ///< empty: the embedded sample (data/tum_fr1_rpy)
  std::filesystem::path out = "relight-out";
  std::string frames;              ///< "A:B" range, empty = all
  int loops = 1;                   ///< play the (ranged) sequence this many times
  std::optional<PinholeIntrinsics> intrinsics;  ///< a preset (kIntrinsicsPresets) overriding the sequence's own
  bool quiet = false;
  bool write_frames = true;        ///< per-frame PNGs under out/frames
  PreviewFrames previews = PreviewFrames::Shown;        ///< which frames get the inner buffers' pictures
  vk::BackendPolicy backend = vk::BackendPolicy::Auto;  ///< see vk/backend.h
  std::string device;              ///< Vulkan device selector (index, type or name part)
  /// AprilTag layout for the marker pose: "auto" (the sequence's scene.json when it has a tag),
  /// "none", or a layout/scene JSON file.
  std::string markers = "auto";
  /// Camera pose source (capture/camera_tracking_stage.h); none: auto.
  std::optional<capture::PoseSource> pose;
  bool skip_bad_frames = false;  ///< TUM frames that cannot be read: warn and skip instead of failing
  GeometryMethod geometry = GeometryMethod::Method1;
  Method2Normals method2_normals = Method2Normals::Filtered;
  /// Differential rendering (render/dir_stage.h) runs when there is an object or a virtual light.
  std::vector<std::filesystem::path> objects;  ///< .obj / .gltf / .glb
  std::vector<std::string> places;             ///< x,y,z[,yaw[,scale]] (world), see object_placement_stage.h
  std::vector<std::string> places_at;          ///< u,v[,yaw[,scale]]: on the surface at a first-frame pixel
  std::vector<std::string> places_on_plane;    ///< [yaw[,scale]]: on the dominant support plane
  /// Pre-modelled objects of the real scene (a real mirror or glass), one --real-place each.
  std::vector<std::filesystem::path> real_objects;
  std::vector<std::string> real_places;  ///< x,y,z[,yaw[,scale]] (world) per real object
  /// The main job (`relight replay` on the embedded sample with nothing to render) renders the
  /// shipped pebble on the sample's support plane, lit by the shipped probe; this turns it off.
  bool no_object = false;
  /// Lights JSON of `relight lights` (constant real lights), or "estimate": from the frames.
  std::filesystem::path lights;
  /// The light probe stream the real lights are extracted from every frame (app/probe_input.h):
  /// a folder with probe.txt, a list, an image, a video or a camera; empty: the sequence's own
  /// probe.txt or probe.hdr; without any, the lights are estimated from the frames (as for the
  /// main job's sample, recorded without a probe).
  std::string probe;
  ProbeInputOptions probe_input;
  std::vector<std::string> virtual_lights;     ///< x,y,z,intensity[,r,g,b]
  std::vector<std::string> virtual_spots;      ///< x,y,z,tx,ty,tz,angle,intensity[,r,g,b]
  std::vector<std::string> real_spots;         ///< the same, for lamps of the real scene
  /// A tracked real lamp (tracked_lamp_stage.h): id,size,angle,intensity[,r,g,b] of its tag and
  /// light, and the light's x,y,z[,ax,ay,az] in the tag's frame; empty: none.
  std::string real_spot_tag;
  std::string real_spot_tag_offset;
  int vpls = 64;                               ///< first-bounce light samples per frame
  /// How the real directional lights (a probe's, an estimate's, a lights file's) reach the scene.
  render::EnvironmentLight environment = render::EnvironmentLight::Directional;
  /// The real directional lights within this many degrees of each other light the scene as one
  /// (render::DirStageOptions::merge_lights_degrees); 0: each as extracted.
  float merge_lights_degrees = 0.f;
  render::VplBudget vpl_budget = render::VplBudget::ByPower;  ///< render/vpl/vpl.h
  std::vector<float> vpl_weights;              ///< per light (lights file order, then virtual lights)
  int vpl_bounces = 1;                         ///< indirect bounces carried by VPLs (render/vpl.h)
  /// Grid stride of the reconstruction's coarse copy (shadow casters, VPL surfaces), in pixels at
  /// 640 across (render/dir/dir_stage.h's DirStageOptions::coarse_mesh_stride); 2 or less: none.
  int coarse_mesh_stride = render::DirStageOptions{}.coarse_mesh_stride;
  render::BounceMethod bounce_method = render::BounceMethod::RayTraced;  ///< how bounces >= 2 find surfaces
  float bounce_share = render::VplOptions{}.bounce_share;  ///< BounceMethod::PreviousFrame's share of --vpls
  render::VplSource vpl_source = render::VplSource::RayTraced;           ///< where spot lights' first VPLs come from
  RealAlbedo real_albedo = RealAlbedo::Pixel;
  float exposure = 1.f;  ///< tone mapping of the rendered light (exposure operator)
  colormap::ToneOperator tone_map = colormap::ToneOperator::Exposure;  ///< --tone-map (colormap/tone_map.h)
  double tone_key = 0.18;                                              ///< Reinhard's key a
  double tone_adaptation_s = 0.5;                                      ///< Reinhard's adaptation time constant
  /// The camera's artefacts on the virtual layer (--camera-artefacts, colormap/camera_look.h).
  std::string camera_artefacts = "all";
  double exposure_time_s = 1.0 / 30.0;         ///< the colour camera's exposure (motion blur)
  /// --composite (render/dir/composite.h); unset: additive, or multiplicative for the main job.
  std::optional<render::CompositeRule> composite;
  bool write_buffers = false;                  ///< L_rv and L_r per frame as EXR
  /// Colour mapping of the rendered light to the camera (colormap/).
  colormap::ColorMapMethod colormap = colormap::ColorMapMethod::Statistics;
  colormap::PolynomialModel colormap_model = colormap::PolynomialModel::Affine3x4;  ///< sample mapping
  bool channel_swap = false;                  ///< sample mapping: add channel-permuted pairs
  bool video = true;                           ///< composite.mp4
  /// A window showing the final picture as it is made (live_view.h), with `view_side` (a buffer:
  /// color, depth, normals, ... of view_stage.h's kViewSides; none: nothing) beside it.
  bool view = false;
  std::optional<PreviewBuffer> view_side;
  /// `relight live`: the device the frames come from (it has no sequence folder; errors name it).
  std::string live_device;
  /// `relight live`: the folder with scene.json / probe.hdr the device serves (relight's own
  /// driver, OpenNiSource::scene_folder), which then takes the sequence folder's part: its
  /// lights, its tag layout for --markers auto, the synthetic default placement.
  std::filesystem::path device_scene;
};


/// A built replay graph with the Vulkan context its stages use (the context outlives the graph).
struct ReplayPipeline {
  std::unique_ptr<relight::vk::VulkanContext> vulkan;
  std::unique_ptr<app::LiveView> view;  ///< with --view; outlives the graph, whose view stage draws into it
  std::unique_ptr<FrameGraph> graph;
  std::string compute;  ///< one line: which backend runs the per-pixel stages, on which device
  app::MarkerTrajectoryStage* markers = nullptr;  ///< set when the marker pose runs
  app::CameraTrajectoryStage* trajectory = nullptr;  ///< the tracked pose of every frame
  app::ObjectPlacementStage* placement = nullptr;  ///< set when there are virtual objects
  app::LatencyStage* latency = nullptr;           ///< capture to final picture, every frame
  lights::ProbeStreamStage* probe = nullptr;      ///< set when the real lights come from a probe
  brdf::LightEstimationStage* light_estimation = nullptr;  ///< set with --lights estimate
  std::string lights_estimated_because;  ///< RealLightSource::fallback: why, when nothing asked for it
  app::TrackedLampStage* tracked_lamp = nullptr;           ///< set with --real-spot-tag
  render::CompositeRule composite_rule = render::CompositeRule::Additive;  ///< as resolved for this run
  render::CameraLookStage* camera_look = nullptr;          ///< set with --camera-artefacts other than none
  colormap::ToneMapStage* tone_map = nullptr;              ///< set when the DIR stage is in the graph
  render::VplStage* vpls = nullptr;                        ///< set when the DIR stage is in the graph
  const render::DirRenderStage* dir = nullptr;             ///< likewise (report.json's dir_steps)
  app::ViewStage* view_stage = nullptr;           ///< with --view
  bool renders = false;                           ///< the DIR stage is in the graph
  int extracted_lights = 0;                       ///< lights extracted per frame (probe or estimate); 0: none
  /// The buffer with the final picture: "composite_mapped" with colour mapping, else "composite".
  BufferName<ColorImage> final_composite = kComposite;
  app::ReportCollectorStage* report = nullptr;    ///< gathers report.html's pictures, materials, lights
  brdf::BrdfPreviewStage* brdf_preview = nullptr;  ///< set when there are virtual objects
  ReplayPipeline();
  ~ReplayPipeline();
  ReplayPipeline(ReplayPipeline&&) noexcept;
};

/// The folder holding the embedded sample data: $RELIGHT_DATA, else the source tree's data/.
[[nodiscard]] std::filesystem::path data_folder();
[[nodiscard]] std::filesystem::path default_sequence();

/// The options with the main job's content filled in: on the embedded sample (no sequence,
/// no live device) with no object and no virtual light, and without `no_object`, the shipped
/// glossy pebble on the support plane, lit from the shipped probe unless `lights` is given.
[[nodiscard]] ReplayOptions with_main_job_defaults(ReplayOptions options);

/// Creates the Vulkan context the options ask for and the replay graph: source, depth filter, writer.
[[nodiscard]] ReplayPipeline build_replay_pipeline(std::unique_ptr<capture::FrameSource> source,
                                                   const ReplayOptions& options);
[[nodiscard]] std::unique_ptr<capture::FrameSource> open_replay_source(const ReplayOptions& options);

/// The report.json sections every run shares (replay, live): the view's counts, the marker pose
/// (with its no-tag warning on stderr), tracking, latency, and where each object was placed
/// (also on stderr unless quiet).
void add_pipeline_summaries(nlohmann::ordered_json& report, const ReplayPipeline& pipeline, const ReplayOptions& options);

/// Where the dir stage's time went, per step (report.json's dir_steps): the medians over the
/// frames of DirRenderStage::step_timings, the G-buffer's and shadow maps' from the device's
/// timestamps; on a CPU device the ISMs are splatted while the device rasterises, so the steps
/// can add up to more than the stage. None on the CPU backend.
[[nodiscard]] std::optional<nlohmann::ordered_json> dir_steps_json(const render::DirRenderStage& stage);

/// Runs the whole replay; returns the process exit code. Throws relight::Error on bad input.
int run_replay(const ReplayOptions& options);

}  // namespace relight::app
