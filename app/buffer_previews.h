#pragma once
// 8-bit pictures of named frame-graph buffers, for people to look at: colour images as they are,
// depth maps in false colour (depth_preview), normal maps colour-coded (normal_preview), the
// virtual coverage as grey (0 real .. 255 virtual). Shared by
// the per-frame PNG writer and the report's contact sheet so both show the same pictures.
// Reads: every buffer registered with add() before the owning stage declares its inputs.
#include <functional>
#include <string>
#include <vector>

#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/render/differential_images.h"

namespace relight::app {

class BufferPreviews {
 public:
  enum class Kind { Color, Depth, Normals, Coverage };

  void add(std::string buffer, Kind kind) { entries_.push_back({std::move(buffer), kind, {}, {}, {}, {}}); }
  [[nodiscard]] bool empty() const { return entries_.empty(); }
  void declare(StageBuilder& builder);
  /// Calls `visit(buffer name, picture)` for each registered buffer, in registration order.
  void for_each(StageContext& context, const std::function<void(const std::string&, const ColorImage&)>& visit) const;

 private:
  struct Entry {
    std::string buffer;
    Kind kind;
    Read<ColorImage> color;
    Read<DepthMap> depth;
    Read<NormalMap> normals;
    Read<render::CoverageImage> coverage;
  };
  std::vector<Entry> entries_;
};

}  // namespace relight::app
