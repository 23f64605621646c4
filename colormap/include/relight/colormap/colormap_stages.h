#pragma once
// Frame-graph stages of the colour mapping (Knecht §4.5, eqs. 4.18-4.19 / 4.28-4.29).
//
// Every mapping stage reads
//   RadianceImage "L_r"   the renderer's image of the reconstructed real scene (linear, HDR)
//   RadianceImage "L_rv"  the same with the virtual objects (differs from L_r exactly on them)
//   ColorImage    "color" the camera image (8-bit sRGB)
// and writes
//   RadianceImage "delta_L" = tau(TM(L_rv)) - tau(TM(L_r)) in camera-linear sRGB, and
//   ColorMapping  "color_mapping" = this frame's tau (color_mapping.h).
// The composite stage reads "color" and "delta_L" and writes ColorImage "color_mapped" =
// sRGB(L_cam + delta_L). Names are configurable through ColorMapBuffers. With
// ColorMapBuffers::tone_map (ToneMap "tone_map", tone_map_stage.h) the mapping stages read each
// frame's operator from the graph; without it they keep the one they were made with.
#include <memory>
#include <optional>
#include <string>

#include "relight/colormap/buffers.h"
#include "relight/colormap/color_mapping.h"
#include "relight/colormap/sample_mapping.h"
#include "relight/colormap/statistics_transfer.h"
#include "relight/colormap/statistics_transfer_vk.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/named_values.h"
#include "relight/core/stage_backend.h"

namespace relight::colormap {

enum class ColorMapMethod { None, Sample, Statistics };
inline constexpr std::array<NamedValue<ColorMapMethod>, 3> kColorMapMethodNames{
    {{"none", ColorMapMethod::None}, {"sample", ColorMapMethod::Sample}, {"stats", ColorMapMethod::Statistics}}};

struct ColorMapBuffers {
  BufferName<RadianceImage> real = kRealRadiance;
  BufferName<RadianceImage> real_virtual = kRealVirtualRadiance;
  BufferName<ColorImage> camera = kColor;
  BufferName<RadianceImage> delta = kDeltaRadiance;
  BufferName<ColorMapping> mapping = kColorMapping;
  BufferName<ColorImage> mapped = kColorMapped;
  std::optional<BufferName<ToneMap>> tone_map;  ///< the per-frame operator, when a stage writes one
};

/// The inputs every mapping stage reads.
struct ColorMapInputs {
  Read<RadianceImage> real, real_virtual;
  Read<ColorImage> camera;
  std::optional<Read<ToneMap>> tone_map;

  static ColorMapInputs declare(StageBuilder& builder, const ColorMapBuffers& buffers, bool camera = true);
  /// This frame's operator: the graph's, or `fixed` without a tone_map buffer.
  [[nodiscard]] ToneMap frame_tone_map(StageContext& context, const ToneMap& fixed) const;
};

/// Statistics-based, CPU (statistics_transfer.h).
class StatisticsColorMapCpuStage final : public Stage {
 public:
  explicit StatisticsColorMapCpuStage(ToneMap tm = {}, ColorMapBuffers buffers = {});
  [[nodiscard]] std::string name() const override { return "colormap_statistics"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const ReinhardTransfer& last_transfer() const { return transfer_; }

 private:
  ToneMap tm_;
  ColorMapBuffers buffers_;
  ColorMapInputs inputs_;
  Write<RadianceImage> delta_;
  Write<ColorMapping> mapping_;
  ReinhardTransfer transfer_;
};

/// Statistics-based, Vulkan (statistics_transfer_vk.h); same buffers. The graph must be built
/// with `&context.transfer()`.
class StatisticsColorMapVkStage final : public Stage {
 public:
  explicit StatisticsColorMapVkStage(vk::VulkanContext& context, ToneMap tm = {}, ColorMapBuffers buffers = {});
  [[nodiscard]] std::string name() const override { return "colormap_statistics"; }
  [[nodiscard]] Backend backend() const override { return Backend::Vulkan; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const ReinhardTransfer& last_transfer() const { return transfer_; }

 private:
  StatisticsColorMapVk mapper_;
  ColorMapBuffers buffers_;
  ColorMapInputs inputs_;
  Write<RadianceImage> delta_;
  Write<ColorMapping> mapping_;
  ReinhardTransfer transfer_;
};

/// Sample-based, CPU (sample_mapping.h); keeps the smoothed coefficients across frames.
class SampleColorMapStage final : public Stage {
 public:
  explicit SampleColorMapStage(SampleMappingOptions options = {}, ColorMapBuffers buffers = {});
  [[nodiscard]] std::string name() const override { return "colormap_sample"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const ColorMatrix& coefficients() const { return mapper_.coefficients(); }

 private:
  SampleColorMapper mapper_;
  ColorMapBuffers buffers_;
  ColorMapInputs inputs_;
  Write<RadianceImage> delta_;
  Write<ColorMapping> mapping_;
};

/// No mapping (the "none" method): delta_L = TM(L_rv) - TM(L_r).
class IdentityColorMapStage final : public Stage {
 public:
  explicit IdentityColorMapStage(ToneMap tm = {}, ColorMapBuffers buffers = {});
  [[nodiscard]] std::string name() const override { return "colormap_none"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  ToneMap tm_;
  ColorMapBuffers buffers_;
  ColorMapInputs inputs_;
  Write<RadianceImage> delta_;
  Write<ColorMapping> mapping_;
};

/// Eq. 4.29: reads "color" and "delta_L", writes ColorImage "color_mapped".
class ColorMapCompositeStage final : public Stage {
 public:
  explicit ColorMapCompositeStage(ColorMapBuffers buffers = {}) : buffers_(std::move(buffers)) {}
  [[nodiscard]] std::string name() const override { return "colormap_composite"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  ColorMapBuffers buffers_;
  Read<ColorImage> camera_;
  Read<RadianceImage> delta_;
  Write<ColorImage> mapped_;
};

/// The mapping stage for a method and backend (Vulkan only exists for Statistics; it needs a
/// non-null `context`, else relight::LogicError).
[[nodiscard]] std::unique_ptr<Stage> make_color_map_stage(ColorMapMethod method, Backend backend,
                                                          vk::VulkanContext* context,
                                                          const SampleMappingOptions& options = {},
                                                          ColorMapBuffers buffers = {});

}  // namespace relight::colormap
