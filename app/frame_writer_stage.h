#pragma once
// Sink stage of `relight replay`: writes, per frame, the buffers a person wants to look at into
// DIR/frames/ as PNG (colour as it is; depth as a false-colour preview) or EXR (radiance), each
// file atomically.
// Reads: the buffers registered with add_color()/add_depth()/add_normals() before the stage joins the graph.
#include <filesystem>
#include <string>
#include <vector>

#include "relight/core/frame_graph.h"
#include "relight/core/image.h"

namespace relight::app {

class FrameWriterStage final : public Stage {
 public:
  explicit FrameWriterStage(std::filesystem::path folder) : folder_(std::move(folder)) {}
  void add_color(std::string buffer) { color_names_.push_back(std::move(buffer)); }
  void add_depth(std::string buffer) { depth_names_.push_back(std::move(buffer)); }
  /// A NormalMap, written as relight::normal_preview's colour coding.
  void add_normals(std::string buffer) { normal_names_.push_back(std::move(buffer)); }
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
  std::vector<std::string> color_names_;
  std::vector<std::string> depth_names_;
  std::vector<Read<ColorImage>> colors_;
  std::vector<Read<DepthMap>> depths_;
  std::vector<std::string> normal_names_;
  std::vector<Read<NormalMap>> normals_;
  std::vector<std::string> radiance_names_;
  std::vector<Read<RadianceImage>> radiances_;
};

}  // namespace relight::app
