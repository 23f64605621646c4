#include "report_collector_stage.h"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace relight::app {

namespace {

Thumbnail make_thumbnail(const std::string& buffer, const ColorImage& picture, int height) {
  const cv::Mat rgb(picture.height(), picture.width(), CV_8UC3, const_cast<Rgb8*>(picture.data()));
  const int width = std::max(1, picture.width() * height / std::max(1, picture.height()));
  cv::Mat small;
  cv::resize(rgb, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  cv::cvtColor(small, small, cv::COLOR_RGB2BGR);
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", small, jpeg, {cv::IMWRITE_JPEG_QUALITY, 85});
  return {buffer, std::string(jpeg.begin(), jpeg.end()), width, height};
}

}  // namespace

ReportCollectorStage::ReportCollectorStage(std::int64_t total_frames, int rows, int thumbnail_height)
    : total_frames_(std::max<std::int64_t>(total_frames, 0)),
      rows_(std::max(rows, 2)),
      thumbnail_height_(std::max(thumbnail_height, 16)) {}

void ReportCollectorStage::declare(StageBuilder& builder) {
  previews_.declare(builder);
  if (materials_name_) materials_ = builder.read(*materials_name_);
  if (lights_name_) lights_ = builder.read(*lights_name_);
}

std::optional<std::size_t> ReportCollectorStage::row_for(std::int64_t frame) const {
  if (total_frames_ == 0) {  // unknown length: the first frame, then a rolling latest one
    if (frame == 0) return 0;
    if (frame % 15 == 0) return 1;
    return std::nullopt;
  }
  const std::int64_t rows = std::min<std::int64_t>(rows_, total_frames_);
  for (std::int64_t row = 0; row < rows; ++row) {
    const std::int64_t chosen = rows == 1 ? 0 : row * (total_frames_ - 1) / (rows - 1);
    if (chosen == frame) return static_cast<std::size_t>(row);
  }
  return std::nullopt;
}

void ReportCollectorStage::run(StageContext& context) {
  if (materials_name_) content_.materials = context.get(materials_).clusters;
  if (lights_name_) content_.lights = context.get(lights_);
  const auto row = row_for(context.frame_index());
  if (!row || previews_.empty()) return;
  ContactSheetRow pictures{context.frame_index(), {}};
  previews_.for_each(context, [&](const std::string& buffer, const ColorImage& picture) {
    pictures.pictures.push_back(make_thumbnail(buffer, picture, thumbnail_height_));
  });
  auto& sheet = content_.contact_sheet;
  if (sheet.size() <= *row) sheet.resize(*row + 1);
  sheet[*row] = std::move(pictures);
}

}  // namespace relight::app
