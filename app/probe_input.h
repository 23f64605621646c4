#pragma once
// The real lights of a `replay` or `live` run, as frame-graph stages: a constant set from a
// lights file, or the light probe stream turned into lights every frame:
//   probe_stream (lights/probe_stream_stage.h) -> light_extraction -> light_smoothing -> "lights"
// (Knecht 2010 §6, dissertation §4.2: the lights follow a probe camera; the smoothing keeps a
// static probe's lights identical and lets a switched lamp through at once).
#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "relight/brdf/light_estimation_stage.h"
#include "relight/core/frame_graph.h"
#include "relight/core/stage_backend.h"
#include "relight/lights/buffers.h"
#include "relight/lights/probe_geometry.h"
#include "relight/lights/probe_stream_stage.h"

namespace relight::app {

inline constexpr std::array<NamedValue<lights::ProbeProjection>, 3> kProbeProjectionNames{
    {{"auto", lights::ProbeProjection::FromAspect},
     {"fisheye", lights::ProbeProjection::Fisheye},
     {"latlong", lights::ProbeProjection::Equirectangular}}};

/// How the probe is read and where it looks (replay's --probe-* options).
struct ProbeInputOptions {
  /// Probe-to-world rotation, degrees about x, then y, then z (world = Rz Ry Rx probe); empty:
  /// identity (a fisheye looking up along world +z with image x = world x, as `relight synth`'s).
  std::vector<double> rotation_degrees;
  /// Where the probe camera sits in the world (metres); empty: at the world's origin (the marker
  /// layout's, which a probe beside the virtual objects is near). Only a tracked lamp needs it:
  /// to find the lamp in the probe's lights (tracked_lamp_stage.h).
  std::vector<double> position;
  lights::ProbeProjection projection = lights::ProbeProjection::FromAspect;
  double fov_degrees = 180.0;      ///< fisheye: the image circle's full field of view
  std::filesystem::path response;  ///< 8-bit probes: response curve file (empty: sRGB)
  double exposure = 1.0;           ///< 8-bit probes: relative exposure
  double tolerance_s = 0.05;       ///< timestamp matching (probe_stream.h)
  double offset_s = 0.0;           ///< video probes: start relative to the first RGB-D frame
  /// Lights extracted per frame; 0: 8, or 64 when they reach the scene as VPLs (replay's
  /// --environment vpls), which costs little per light and samples the probe more finely.
  int lights = 0;
  bool smoothing = true;           ///< light_smoothing between extraction and the lights
};

/// --probe-position as a point (the origin when not given); throws relight::Error unless it is
/// three finite numbers.
[[nodiscard]] Eigen::Vector3d probe_position(const ProbeInputOptions& options);

/// The calibration the options describe; throws relight::Error on a bad rotation or field of view.
[[nodiscard]] lights::ProbeCalibration probe_calibration(const ProbeInputOptions& options);

/// Where the real lights of a run come from.
struct RealLightSource {
  std::filesystem::path lights_file;  ///< constant lights (`relight lights` JSON); else the probe
  std::string probe;                  ///< probe spec (video_probe_stream.h: open_probe_input)
  bool estimate = false;              ///< `--lights estimate`: from the RGB-D frames (brdf/light_estimation.h)
  /// Why the lights are estimated without being asked: "<no_probe>" (nothing else to light the
  /// scene with); empty when the options chose the source.
  std::string fallback;
};

/// The --lights value that estimates the lights from the frames instead of reading a file.
inline constexpr const char* kEstimateLights = "estimate";

/// --lights (a file, or `estimate`), else --probe, else `scene`'s probe.txt, else its probe.hdr;
/// when there is none, the estimate from the frames, with `fallback` = `no_probe` (every TUM
/// recording and most users' own .oni have no probe: they are lit by what their frames show).
[[nodiscard]] RealLightSource real_light_source(const std::filesystem::path& lights_file, const std::string& probe,
                                                const std::optional<std::filesystem::path>& scene,
                                                const std::string& no_probe);

/// The stages add_real_light_stages added that report.json summarises (null when absent).
struct RealLightStages {
  lights::ProbeStreamStage* probe = nullptr;
  brdf::LightEstimationStage* estimation = nullptr;
};

/// Adds the stages that write `output` (lights::kLights unless a tracked lamp joins them later,
/// tracked_lamp_stage.h): a constant set from a lights file, or the probe stream (or the
/// estimate's environment map) -> light_extraction -> light_smoothing.
RealLightStages add_real_light_stages(FrameGraph& graph, const RealLightSource& source,
                                      const ProbeInputOptions& options, Backend per_pixel, vk::VulkanContext* context,
                                      BufferName<lights::LightSet> output = lights::kLights);

}  // namespace relight::app
