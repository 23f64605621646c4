#pragma once
// What BRDF estimation found, as one picture per frame for a person to look at (Knecht §4.4):
// five panels side by side - the camera image, the highlight mask, the diffuse reflectance k_d,
// the K-means clusters in false colours, and the Phong re-render with the estimated materials.
//
// BrdfPreviewStage reads ColorImage "color", Mask "highlight_mask", RadianceImage "kd",
// Materials "materials", PositionMap "positions", NormalMap "normals", LightSet "lights" and
// FrameInfo "frame" (names as BrdfBuffers); writes ColorImage "brdf_preview".
#include <cstdint>
#include <functional>
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
  /// Makes the mosaic only for the frames `wanted` accepts (an empty picture otherwise): a run
  /// that writes no frames shows it only on report.html's few contact-sheet rows, and the
  /// re-render behind it costs as much as the BRDF estimation's own stages.
  void only_for(std::function<bool(std::int64_t)> wanted) { wanted_ = std::move(wanted); }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  BrdfBuffers buffers_;
  BufferName<ColorImage> output_name_;
  std::function<bool(std::int64_t)> wanted_;  ///< empty: every frame
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
