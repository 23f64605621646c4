#include "probe_input.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "constant_stage.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/lights/light_output.h"
#include "relight/lights/light_smoothing.h"
#include "relight/lights/light_stages.h"
#include "video_probe_stream.h"

namespace relight::app {

namespace fs = std::filesystem;

lights::ProbeCalibration probe_calibration(const ProbeInputOptions& options) {
  lights::ProbeCalibration calibration;
  calibration.projection = options.projection;
  calibration.centred_on_image = true;
  if (!(options.fov_degrees > 0.0 && options.fov_degrees <= 360.0)) {
    throw Error("--probe-fov must be in (0, 360] degrees");
  }
  calibration.fisheye.max_theta = 0.5 * options.fov_degrees * std::numbers::pi / 180.0;
  if (!options.rotation_degrees.empty()) {
    if (options.rotation_degrees.size() != 3) throw Error("--probe-rotation needs three angles rx,ry,rz in degrees");
    const auto radians = [&](std::size_t i) { return options.rotation_degrees[i] * std::numbers::pi / 180.0; };
    for (double angle : options.rotation_degrees) {
      if (!std::isfinite(angle)) throw Error("--probe-rotation: the angles must be finite");
    }
    calibration.probe_to_world = (Eigen::AngleAxisd(radians(2), Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(radians(1), Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(radians(0), Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
  }
  return calibration;
}

RealLightSource real_light_source(const fs::path& lights_file, const std::string& probe,
                                  const std::optional<fs::path>& scene, const std::string& no_probe) {
  RealLightSource source;
  if (lights_file == kEstimateLights) {
    source.estimate = true;
    return source;
  }
  source.lights_file = lights_file;
  source.probe = probe;
  if (!lights_file.empty() || !probe.empty()) return source;
  std::error_code ec;
  if (scene && scene->extension() != ".oni") {
    for (const char* name : {"probe.txt", "probe.hdr"}) {
      source.probe = (*scene / name).string();
      if (fs::is_regular_file(source.probe, ec)) return source;
    }
  }
  source.probe.clear();
  source.estimate = true;
  source.fallback = no_probe;
  return source;
}

namespace {
lights::ProbeStreamStage& add_probe_stream_stage(FrameGraph& graph, const RealLightSource& source,
                                                 const ProbeInputOptions& options) {
  if (!(options.tolerance_s >= 0.0)) throw Error("--probe-tolerance must not be negative");
  lights::ProbeResponse response =
      options.response.empty() ? lights::ProbeResponse{} : lights::read_probe_response(options.response);
  if (!(options.exposure > 0.0)) throw Error("--probe-exposure must be positive");
  response.exposure = options.exposure;
  lights::ProbeMatchOptions matching;
  matching.tolerance_s = options.tolerance_s;
  matching.offset_s = options.offset_s;
  return graph.emplace<lights::ProbeStreamStage>(open_probe_input(source.probe, response), matching);
}
}  // namespace

Eigen::Vector3d probe_position(const ProbeInputOptions& options) {
  if (options.position.empty()) return Eigen::Vector3d::Zero();
  if (options.position.size() != 3 ||
      !std::all_of(options.position.begin(), options.position.end(), [](double v) { return std::isfinite(v); }))
    throw Error("--probe-position needs three finite coordinates x,y,z in metres");
  return {options.position[0], options.position[1], options.position[2]};
}

RealLightStages add_real_light_stages(FrameGraph& graph, const RealLightSource& source,
                                      const ProbeInputOptions& options, Backend per_pixel, vk::VulkanContext* context,
                                      BufferName<lights::LightSet> output) {
  if (!source.lights_file.empty()) {
    graph.emplace<ConstantStage<lights::LightSet>>(
        output, lights::lights_from_json(read_text_file(source.lights_file), source.lights_file.string()));
    return {};
  }
  if (options.lights < 1 || options.lights > 4096) throw Error("--probe-lights must be 1 to 4096");
  RealLightStages stages;
  lights::LightExtractionOptions extraction;
  extraction.lights = options.lights;
  if (source.estimate) {
    stages.estimation = &graph.emplace<brdf::LightEstimationStage>();
    extraction.calibration = lights::ProbeCalibration::equirectangular();
  } else {
    stages.probe = &add_probe_stream_stage(graph, source, options);
    extraction.calibration = probe_calibration(options);
  }
  // Without smoothing the extracted lights are the lights (for comparisons: the flicker it removes).
  const lights::LightExtractionBuffers buffers{kProbe, options.smoothing ? lights::kLightsRaw : output};
  graph.add(lights::make_light_extraction_stage(per_pixel, context, extraction, buffers));
  if (options.smoothing)
    graph.emplace<lights::LightSmoothingStage>(lights::LightSmoothingOptions{},
                                               lights::LightSmoothingBuffers{lights::kLightsRaw, output});
  return stages;
}

}  // namespace relight::app
