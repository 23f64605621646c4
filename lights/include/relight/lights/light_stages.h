#pragma once
// Frame-graph stage that turns the light probe into lights.
//
//   reads  RadianceImage "probe"       (linear radiance, fisheye or lat-long, see probe_geometry.h)
//   writes LightSet      "lights_raw"  (importance-sampled VPLs or median-cut lights, real = true)
// Add LightSmoothingStage (light_smoothing.h) after it for temporally stable "lights".
// The importance method runs on the CPU (importance_sampling.h) or on Vulkan (same samples).
#include <memory>
#include <string>

#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/named_values.h"
#include "relight/core/stage_backend.h"
#include "relight/lights/buffers.h"
#include "relight/lights/importance_sampling.h"
#include "relight/lights/median_cut.h"

namespace relight::lights {

enum class LightMethod { Importance, MedianCut };
inline constexpr std::array<NamedValue<LightMethod>, 2> kLightMethodNames{
    {{"importance", LightMethod::Importance}, {"median-cut", LightMethod::MedianCut}}};

struct LightExtractionOptions {
  LightMethod method = LightMethod::Importance;
  int lights = 64;
  std::uint64_t seed = 0;  ///< importance only
  ProbeCalibration calibration{};
};

struct LightExtractionBuffers {
  BufferName<RadianceImage> probe = kProbe;
  BufferName<LightSet> lights = kLightsRaw;
};

/// Either method on the CPU, or importance sampling on Vulkan when `context` is not null (made
/// by make_light_extraction_stage, which chooses). Its buffers live on the host either way.
class LightExtractionStage final : public Stage {
 public:
  explicit LightExtractionStage(LightExtractionOptions options, LightExtractionBuffers buffers = {},
                                vk::VulkanContext* context = nullptr);
  ~LightExtractionStage() override;
  [[nodiscard]] std::string name() const override { return "light_extraction"; }
  [[nodiscard]] Backend backend() const override { return context_ ? Backend::Vulkan : Backend::Cpu; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  LightExtractionOptions options_;
  LightExtractionBuffers buffers_;
  vk::VulkanContext* context_;
  ProbeGeometry geometry_;  // rebuilt when the probe size changes
  ImportancePyramid pyramid_;
  std::unique_ptr<ImportanceSamplerVk> vulkan_;
  Read<RadianceImage> probe_;
  Write<LightSet> lights_;
};

/// LightExtractionStage for `backend` (core/stage_backend.h); Backend::Vulkan requires a non-null
/// `context` and LightMethod::Importance (else relight::LogicError).
[[nodiscard]] std::unique_ptr<Stage> make_light_extraction_stage(Backend backend, vk::VulkanContext* context,
                                                                 LightExtractionOptions options,
                                                                 LightExtractionBuffers buffers = {});

/// Runs the chosen method once on a probe (what the stage does per frame).
[[nodiscard]] LightSet extract_lights(const RadianceImage& probe, const LightExtractionOptions& options);

}  // namespace relight::lights
