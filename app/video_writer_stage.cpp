#include "video_writer_stage.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "relight/core/error.h"

namespace relight::app {

VideoWriterStage::VideoWriterStage(std::filesystem::path path, BufferName<ColorImage> buffer, double fps)
    : path_(std::move(path)), buffer_name_(buffer), fps_(fps) {
  // The container comes from the extension, so the temporary name keeps ".mp4".
  partial_ = path_;
  partial_.replace_filename(path_.stem().string() + ".partial" + path_.extension().string());
}

VideoWriterStage::~VideoWriterStage() {
  if (writer_) {
    writer_->release();
    std::error_code ec;
    std::filesystem::remove(partial_, ec);  // finish() never ran: no final file
  }
}

void VideoWriterStage::declare(StageBuilder& builder) { buffer_ = builder.read(buffer_name_); }

void VideoWriterStage::run(StageContext& context) {
  const ColorImage& image = context.get(buffer_);
  if (!writer_) {
    width_ = image.width();
    height_ = image.height();
    writer_ = std::make_unique<cv::VideoWriter>(partial_.string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps_,
                                                cv::Size(width_, height_));
    if (!writer_->isOpened()) throw Error("cannot write the video " + partial_.string() + " (no MP4 encoder in OpenCV?)");
  }
  if (image.width() != width_ || image.height() != height_)
    throw Error("video " + path_.string() + ": frame " + std::to_string(context.frame_index()) + " changes size");
  // ColorImage is tightly packed RGB8; OpenCV wants BGR.
  const cv::Mat rgb(height_, width_, CV_8UC3, const_cast<Rgb8*>(image.pixels().data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  writer_->write(bgr);
}

void VideoWriterStage::finish() {
  if (!writer_) return;
  writer_->release();
  writer_.reset();
  std::error_code ec;
  std::filesystem::rename(partial_, path_, ec);
  if (ec) throw Error("cannot move " + partial_.string() + " to " + path_.string() + ": " + ec.message());
}

}  // namespace relight::app
