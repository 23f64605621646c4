#pragma once
// Sink stage of `relight replay`: writes, per frame, the buffers a person wants to look at into
// DIR/frames/ as PNG (colour as it is; depth as a false-colour preview) or EXR (radiance), each
// file atomically.
// Reads: the buffers registered with add() before the stage joins the graph.
#include <filesystem>
#include <string>
#include <vector>

#include "buffer_previews.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"

namespace relight::app {

class FrameWriterStage final : public Stage {
 public:
  explicit FrameWriterStage(std::filesystem::path folder) : folder_(std::move(folder)) {}
  /// A PNG per frame: colour as it is, depth in false colour, a NormalMap as
  /// relight::normal_preview's colour coding, a CoverageImage (the virtual share of each pixel)
  /// as grey (buffer_previews.h).
  void add(PreviewBuffer buffer) { previews_.add(buffer); }
  /// A RadianceImage, written as OpenEXR (linear, full range).
  void add(BufferName<RadianceImage> buffer) { radiance_names_.push_back(buffer); }

  [[nodiscard]] std::string name() const override { return "frame_writer"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  [[nodiscard]] std::filesystem::path file_for(std::int64_t frame, const std::string& buffer,
                                               const char* extension = ".png") const;

  std::filesystem::path folder_;
  BufferPreviews previews_;
  std::vector<BufferName<RadianceImage>> radiance_names_;
  std::vector<Read<RadianceImage>> radiances_;
};

}  // namespace relight::app
