#pragma once
// Sink stage that gathers what report.html shows besides timings: small JPEG pictures of a few
// frames' buffers (the contact sheet), a full-resolution close-up of two pictures around the virtual
// objects, and the latest estimated materials and lights.
// Reads: the buffers registered with add_picture(), and optionally a brdf::Materials and a LightSet
// buffer. Writes nothing; the run reads content() after the last frame.
// The frames are chosen evenly over a run of known length; for a run of unknown length (live) the
// first frame and a rolling latest frame (refreshed every 15th frame) are kept.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "buffer_previews.h"
#include "html_report.h"
#include "relight/brdf/materials.h"
#include "relight/core/frame_graph.h"
#include "relight/lights/light_set.h"
#include "relight/render/differential_images.h"

namespace relight::app {

/// Frames on report.html's contact sheet by default.
inline constexpr int kContactSheetRows = 4;

/// The contact-sheet row of `frame` if report.html shows it: `rows` frames chosen evenly over a
/// run of `total_frames`, or for a run of unknown length (0) the first frame and every 15th.
[[nodiscard]] std::optional<std::size_t> contact_sheet_row(std::int64_t frame, std::int64_t total_frames, int rows);

class ReportCollectorStage final : public Stage {
 public:
  /// total_frames: frames the run will process (0 = unknown); rows: frames on the contact sheet;
  /// pictures are scaled to thumbnail_height (wide mosaics such as brdf_preview stay readable).
  ReportCollectorStage(std::int64_t total_frames, int rows = kContactSheetRows, int thumbnail_height = 110);

  void add_picture(PreviewBuffer buffer) { previews_.add(buffer); }
  void collect_materials(BufferName<brdf::Materials> buffer) { materials_name_ = buffer; }
  void collect_lights(BufferName<lights::LightSet> buffer) { lights_name_ = buffer; }
  /// A close-up of `before` and `after` around the pixels `coverage` covers, from the last shown
  /// frame where it covers any (report.html's camera look section).
  void add_close_up(BufferName<ColorImage> before, BufferName<ColorImage> after,
                    BufferName<render::CoverageImage> coverage) {
    close_up_names_ = {before, after, coverage};
  }

  [[nodiscard]] std::string name() const override { return "report"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

  /// Whether the contact sheet (and the close-up) shows this frame (stages that make pictures
  /// only for it ask).
  [[nodiscard]] bool shows(std::int64_t frame) const {
    return contact_sheet_row(frame, total_frames_, rows_).has_value();
  }
  /// Contact sheet, materials and lights gathered so far (timings and graph are the run's to add).
  [[nodiscard]] const ReportContent& content() const { return content_; }

 private:
  std::int64_t total_frames_;
  int rows_;
  int thumbnail_height_;
  BufferPreviews previews_;
  std::optional<BufferName<brdf::Materials>> materials_name_;
  std::optional<BufferName<lights::LightSet>> lights_name_;
  struct CloseUpNames {
    BufferName<ColorImage> before, after;
    BufferName<render::CoverageImage> coverage;
  };
  std::optional<CloseUpNames> close_up_names_;
  Read<ColorImage> close_up_before_, close_up_after_;
  Read<render::CoverageImage> close_up_coverage_;
  Read<brdf::Materials> materials_;
  Read<lights::LightSet> lights_;
  ReportContent content_;
};

}  // namespace relight::app
