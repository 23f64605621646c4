#pragma once
// Sink stage of `relight replay`: writes, per frame, the buffers a person wants to look at into
// DIR/frames/ as PNG (colour as it is; depth as a false-colour preview) or EXR (radiance), each
// file atomically. The stage makes the pictures and hands copies to a WriteQueue (write_queue.h),
// whose thread encodes and writes them while the next frames are computed; finish() waits for the
// last. A failed write ends the run with its error at the next frame (or at finish).
// Reads: the buffers registered with add() before the stage joins the graph.
#include <filesystem>
#include <string>
#include <vector>

#include "buffer_previews.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/write_queue.h"

namespace relight::app {

class FrameWriterStage final : public Stage {
 public:
  explicit FrameWriterStage(std::filesystem::path folder) : folder_(std::move(folder)) {}
  /// A PNG per frame: colour as it is, depth in false colour, a NormalMap as
  /// relight::normal_preview's colour coding, a CoverageImage (the virtual share of each pixel)
  /// as grey (buffer_previews.h); for the frames `frames` wants (empty: every frame).
  void add(PreviewBuffer buffer, FrameFilter frames = {}) { previews_.add(buffer, std::move(frames)); }
  /// A RadianceImage, written as OpenEXR (linear, full range).
  void add(BufferName<RadianceImage> buffer) { radiance_names_.push_back(buffer); }

  [[nodiscard]] std::string name() const override { return "frame_writer"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  void finish() override { queue_.drain(); }

 private:
  [[nodiscard]] std::filesystem::path file_for(std::int64_t frame, const std::string& buffer,
                                               const char* extension = ".png") const;

  std::filesystem::path folder_;
  BufferPreviews previews_;
  std::vector<BufferName<RadianceImage>> radiance_names_;
  std::vector<Read<RadianceImage>> radiances_;
  /// About two frames of pictures: enough to overlap a frame's writing with the next frame,
  /// little enough memory (a 640x480 picture is 0.9 MB, a radiance image 3.7 MB).
  WriteQueue queue_{16};
};

}  // namespace relight::app
