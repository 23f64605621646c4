#pragma once
// 8-bit pictures of named frame-graph buffers, for people to look at: colour images as they are,
// depth maps in false colour (depth_preview), normal maps colour-coded (normal_preview), the
// virtual coverage as grey (0 real .. 255 virtual). Shared by the per-frame PNG writer, the
// report's contact sheet and the view, so all show the same pictures. The buffer's type says how
// it is drawn.
// Reads: every buffer registered with add() before the owning stage declares its inputs.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/render/differential_images.h"

namespace relight::app {

/// A buffer that can be drawn, by its typed name.
using PreviewBuffer = std::variant<BufferName<ColorImage>, BufferName<DepthMap>, BufferName<NormalMap>,
                                   BufferName<render::CoverageImage>>;

/// Which frames a picture is wanted for (frame index -> wanted); empty: every frame.
using FrameFilter = std::function<bool(std::int64_t)>;

class BufferPreviews {
 public:
  void add(PreviewBuffer buffer, FrameFilter frames = {}) { entries_.push_back({buffer, std::move(frames), {}}); }
  [[nodiscard]] bool empty() const { return entries_.empty(); }
  void declare(StageBuilder& builder);
  /// Calls `visit(buffer name, picture)` for each registered buffer that this frame is wanted
  /// for, in registration order (the others are not drawn).
  void for_each(StageContext& context, const std::function<void(const std::string&, const ColorImage&)>& visit) const;

 private:
  struct Entry {
    PreviewBuffer buffer;
    FrameFilter frames;
    std::variant<Read<ColorImage>, Read<DepthMap>, Read<NormalMap>, Read<render::CoverageImage>> handle;
  };
  std::vector<Entry> entries_;
};

}  // namespace relight::app
