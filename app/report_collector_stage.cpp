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

/// Pixels of context around the covered box, and the smallest crop (4:3).
constexpr int kCloseUpMargin = 24, kCloseUpMinWidth = 160, kCloseUpMinHeight = 120, kCloseUpScale = 2;

/// The same crop of both pictures around the covered pixels, scaled up by nearest pixel, as PNG;
/// none where nothing is covered.
std::optional<CloseUp> close_up(std::int64_t frame, const ColorImage& before, const ColorImage& after,
                                const render::CoverageImage& coverage) {
  if (!before.same_shape(coverage) || !after.same_shape(coverage)) return std::nullopt;
  int top = coverage.height(), bottom = -1, left = coverage.width(), right = -1;
  for (int r = 0; r < coverage.height(); ++r)
    for (int c = 0; c < coverage.width(); ++c)
      if (coverage(r, c) > 0.f)
        top = std::min(top, r), bottom = std::max(bottom, r), left = std::min(left, c), right = std::max(right, c);
  if (bottom < 0) return std::nullopt;
  const int width = std::min(coverage.width(), std::max(kCloseUpMinWidth, right - left + 1 + 2 * kCloseUpMargin));
  const int height = std::min(coverage.height(), std::max(kCloseUpMinHeight, bottom - top + 1 + 2 * kCloseUpMargin));
  const int x0 = std::clamp((left + right) / 2 - width / 2, 0, coverage.width() - width);
  const int y0 = std::clamp((top + bottom) / 2 - height / 2, 0, coverage.height() - height);
  const auto encode = [&](const std::string& name, const ColorImage& picture) {
    const cv::Mat rgb(picture.height(), picture.width(), CV_8UC3, const_cast<Rgb8*>(picture.data()));
    cv::Mat big;
    cv::resize(rgb(cv::Rect(x0, y0, width, height)), big, cv::Size(), kCloseUpScale, kCloseUpScale, cv::INTER_NEAREST);
    cv::cvtColor(big, big, cv::COLOR_RGB2BGR);
    std::vector<unsigned char> png;
    cv::imencode(".png", big, png);
    return Thumbnail{name, std::string(png.begin(), png.end()), big.cols, big.rows};
  };
  return CloseUp{frame, encode("as rendered", before), encode("with the camera's look", after)};
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
  if (close_up_names_) {
    close_up_before_ = builder.read(close_up_names_->before);
    close_up_after_ = builder.read(close_up_names_->after);
    close_up_coverage_ = builder.read(close_up_names_->coverage);
  }
}

std::optional<std::size_t> contact_sheet_row(std::int64_t frame, std::int64_t total_frames, int rows_wanted) {
  if (total_frames == 0) {  // unknown length: the first frame, then a rolling latest one
    if (frame == 0) return 0;
    if (frame % 15 == 0) return 1;
    return std::nullopt;
  }
  const std::int64_t rows = std::min<std::int64_t>(rows_wanted, total_frames);
  for (std::int64_t row = 0; row < rows; ++row) {
    const std::int64_t chosen = rows == 1 ? 0 : row * (total_frames - 1) / (rows - 1);
    if (chosen == frame) return static_cast<std::size_t>(row);
  }
  return std::nullopt;
}

void ReportCollectorStage::run(StageContext& context) {
  if (materials_name_) content_.materials = context.get(materials_).clusters;
  if (lights_name_) content_.lights = context.get(lights_);
  const auto row = contact_sheet_row(context.frame_index(), total_frames_, rows_);
  if (row && close_up_names_) {
    if (auto picture = close_up(context.frame_index(), context.get(close_up_before_), context.get(close_up_after_),
                                context.get(close_up_coverage_)))
      content_.camera_look = std::move(picture);
  }
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
