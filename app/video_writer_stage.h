#pragma once
// Sink stage of `relight replay` / `live`: appends one ColorImage buffer per frame to an MP4
// video (OpenCV VideoWriter, MPEG-4 part 2 'mp4v', which Debian's OpenCV writes through FFmpeg).
// The video grows under a temporary name and takes its final name in finish(), so an interrupted
// or failed run never leaves a half-written file under the final name.
// Reads: the ColorImage named at construction.
#include <filesystem>
#include <memory>
#include <string>

#include "relight/core/frame_graph.h"
#include "relight/core/image.h"

namespace cv {
class VideoWriter;
}

namespace relight::app {

class VideoWriterStage final : public Stage {
 public:
  VideoWriterStage(std::filesystem::path path, BufferName<ColorImage> buffer, double fps = 30.0);
  ~VideoWriterStage() override;

  [[nodiscard]] std::string name() const override { return "video_writer"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  void finish() override;

 private:
  std::filesystem::path path_, partial_;
  BufferName<ColorImage> buffer_name_;
  double fps_;
  Read<ColorImage> buffer_;
  std::unique_ptr<cv::VideoWriter> writer_;
  int width_ = 0, height_ = 0;
};

}  // namespace relight::app
