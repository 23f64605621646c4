#pragma once
// Sink stage of `relight replay`: writes, per frame, the buffers a person wants to look at into
// DIR/frames/ as PNG (colour as it is; depth as a false-colour preview) or EXR (radiance), each
// file atomically.
// Reads: the buffers registered with add_color()/add_depth()/add_normals() before the stage joins the graph.
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
  void add_color(std::string buffer) { previews_.add(std::move(buffer), BufferPreviews::Kind::Color); }
  void add_depth(std::string buffer) { previews_.add(std::move(buffer), BufferPreviews::Kind::Depth); }
  /// A NormalMap, written as relight::normal_preview's colour coding.
  void add_normals(std::string buffer) { previews_.add(std::move(buffer), BufferPreviews::Kind::Normals); }
  /// A CoverageImage (the virtual share of each pixel), written as grey.
  void add_coverage(std::string buffer) { previews_.add(std::move(buffer), BufferPreviews::Kind::Coverage); }
  /// A RadianceImage, written as OpenEXR (linear, full range).
  void add_radiance(std::string buffer) { radiance_names_.push_back(std::move(buffer)); }

  [[nodiscard]] std::string name() const override { return "frame_writer"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  [[nodiscard]] std::filesystem::path file_for(std::int64_t frame, const std::string& buffer,
                                               const char* extension = ".png") const;

  std::filesystem::path folder_;
  BufferPreviews previews_;
  std::vector<std::string> radiance_names_;
  std::vector<Read<RadianceImage>> radiances_;
};

}  // namespace relight::app
