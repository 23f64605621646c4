#pragma once
// Temporal stability of the extracted lights.
//
// Importance sampling reuses the same point set every frame (fixed seed), so a static probe
// already gives the same lights; what flickers on a real camera is sensor noise moving samples
// by a pixel and changing powers a little. smooth_lights blends each light with the light of the
// same index in the previous frame's set (exponential moving average of direction and power)
// when it stayed within `max_jitter`; a light that moved further is new information (a lamp
// switched on or off pulls samples towards or away from it) and is taken as it is. When the
// probe's total power changes by more than `reset_change`, the history is dropped, so a switched
// light shows up in the next frame and a small change within two.
#include <numbers>
#include <string>

#include "relight/core/frame_graph.h"
#include "relight/lights/buffers.h"
#include "relight/lights/light_set.h"

namespace relight::lights {

struct LightSmoothingOptions {
  double blend = 0.5;                                  ///< weight of the new frame, (0, 1]
  double max_jitter = 1.5 * std::numbers::pi / 180.0;  ///< radians
  double reset_change = 0.2;                           ///< relative change of total luminance power
};

/// `previous` may be null (first frame): then `current` comes back unchanged.
[[nodiscard]] LightSet smooth_lights(const LightSet& current, const LightSet* previous,
                                     const LightSmoothingOptions& options = {});

struct LightSmoothingBuffers {
  BufferName<LightSet> input = kLightsRaw;  ///< this frame's extracted lights
  BufferName<LightSet> output = kLights;    ///< smoothed; its previous version is the history
};

/// Reads LightSet `input` and the previous frame's LightSet `output`; writes LightSet `output`.
class LightSmoothingStage final : public Stage {
 public:
  explicit LightSmoothingStage(LightSmoothingOptions options = {}, LightSmoothingBuffers buffers = {})
      : options_(options), buffers_(buffers) {}
  [[nodiscard]] std::string name() const override { return "light_smoothing"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  LightSmoothingOptions options_;
  LightSmoothingBuffers buffers_;
  Read<LightSet> input_;
  ReadPrevious<LightSet> previous_;
  Write<LightSet> output_;
};

}  // namespace relight::lights
