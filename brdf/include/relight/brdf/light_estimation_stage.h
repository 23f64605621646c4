#pragma once
// Frame-graph stage of the light estimate without a probe (light_estimation.h).
//
//   reads  ColorImage    "color_diffuse"  (highlight removal's output)
//          Mask          "highlight_mask" (pixels it skips)
//          PositionMap   "positions", NormalMap "normals" (camera frame)
//          FrameInfo     "frame"          (intrinsics; camera_to_world, identity when unknown)
//   writes RadianceImage "probe"          (the estimated environment, lat-long, world frame)
// The probe's light extraction and smoothing (lights/light_stages.h) turn it into "lights",
// with the calibration lights::ProbeCalibration::equirectangular().
#include <nlohmann/json.hpp>
#include <string>

#include "relight/brdf/light_estimation.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"

namespace relight::brdf {

class LightEstimationStage final : public Stage {
 public:
  explicit LightEstimationStage(LightEstimationOptions options = {}) : estimator_(options) {}
  [[nodiscard]] std::string name() const override { return "light_estimation"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const LightEstimate& estimate() const { return estimator_.estimate(); }
  /// The last frame's estimate (report.json's "light_estimate").
  [[nodiscard]] nlohmann::ordered_json summary() const { return estimator_.estimate().to_json(); }

 private:
  LightEstimator estimator_;
  Read<ColorImage> color_;
  Read<Mask> highlights_;
  Read<PositionMap> positions_;
  Read<NormalMap> normals_;
  Read<FrameInfo> frame_;
  Write<RadianceImage> probe_;
};

}  // namespace relight::brdf
