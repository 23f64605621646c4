#pragma once
// What BRDF estimation found, as one picture per frame for a person to look at (Knecht §4.4):
// five panels side by side - the camera image, the highlight mask, the diffuse reflectance k_d,
// the K-means clusters in false colours, and the Phong re-render with the estimated materials.
//
// BrdfPreviewStage reads ColorImage "color", Mask "highlight_mask", RadianceImage "kd",
// Materials "materials", PositionMap "positions", NormalMap "normals", LightSet "lights" and
// FrameInfo "frame" (names as BrdfBuffers); writes ColorImage "brdf_preview".
#include <string>

#include "relight/brdf/brdf_stages.h"

namespace relight::brdf {

/// Panels: colour | mask (white = highlight) | k_d (sRGB) | clusters (black = none) | re-render
/// (sRGB, clamped). All inputs must have the colour image's size.
[[nodiscard]] ColorImage brdf_preview(const ColorImage& color, const Mask& highlights, const RadianceImage& kd,
                                      const Materials& materials, const RadianceImage& rerender);

class BrdfPreviewStage final : public Stage {
 public:
  explicit BrdfPreviewStage(BrdfBuffers buffers = {}, BufferName<ColorImage> output = kBrdfPreview)
      : buffers_(buffers), output_name_(output) {}
  [[nodiscard]] std::string name() const override { return "brdf_preview"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  BrdfBuffers buffers_;
  BufferName<ColorImage> output_name_;
  Read<ColorImage> color_;
  Read<Mask> highlights_;
  Read<RadianceImage> kd_;
  Read<Materials> materials_;
  Read<PositionMap> positions_;
  Read<NormalMap> normals_;
  Read<lights::LightSet> lights_;
  Read<FrameInfo> frame_;
  Write<ColorImage> preview_;
};

}  // namespace relight::brdf
