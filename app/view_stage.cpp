#include "view_stage.h"

#include <cstdio>

#include "interrupt.h"

namespace relight::app {

namespace {

/// `left` and `right` side by side (the taller sets the height; the rest is black).
ColorImage side_by_side(const ColorImage& left, const ColorImage& right) {
  ColorImage out(left.width() + right.width(), std::max(left.height(), right.height()), Rgb8{0, 0, 0});
  for (int r = 0; r < left.height(); ++r)
    for (int c = 0; c < left.width(); ++c) out(r, c) = left(r, c);
  for (int r = 0; r < right.height(); ++r)
    for (int c = 0; c < right.width(); ++c) out(r, left.width() + c) = right(r, c);
  return out;
}

}  // namespace

ViewStage::ViewStage(LiveView& view, BufferName<ColorImage> picture, std::optional<PreviewBuffer> side)
    : view_(view), picture_name_(picture) {
  if (side) side_.add(*side);
}

void ViewStage::declare(StageBuilder& builder) {
  picture_ = builder.read(picture_name_);
  pose_ = builder.read(capture::kCameraPose);
  frame_ = builder.read(kSourceFrame);
  side_.declare(builder);
}

void ViewStage::run(StageContext& context) {
  const auto now = std::chrono::steady_clock::now();
  recent_.push_back(now);
  if (recent_.size() > 16) recent_.pop_front();
  const double span = std::chrono::duration<double>(recent_.back() - recent_.front()).count();
  const double fps = span > 0 ? static_cast<double>(recent_.size() - 1) / span : 0.0;

  ColorImage picture = context.get(picture_);
  side_.for_each(context, [&picture](const std::string&, const ColorImage& side) { picture = side_by_side(picture, side); });
  const capture::CameraPose& pose = context.get(pose_);
  char line[160];
  std::snprintf(line, sizeof line, "frame %lld   %.1f fps", static_cast<long long>(context.get(frame_).index), fps);
  std::string overlay = line;
  overlay += pose.failure.empty() ? std::string("\ntracking (") + to_string(pose.source) + ")"
                                  : "\nLOST: " + pose.failure + " (holding the last pose)";
  if (dropped_) overlay += "\ndropped " + std::to_string(dropped_());
  if (view_.skipped() > 0) overlay += "\nview skipped " + std::to_string(view_.skipped());
  view_.show(std::move(picture), std::move(overlay));
  view_.wait_while_paused([] { return InterruptGuard::interrupted(); });
}

}  // namespace relight::app
