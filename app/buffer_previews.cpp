#include "buffer_previews.h"

#include "relight/core/image_io.h"

namespace relight::app {

void BufferPreviews::declare(StageBuilder& builder) {
  for (Entry& entry : entries_) {
    switch (entry.kind) {
      case Kind::Color: entry.color = builder.read<ColorImage>(entry.buffer); break;
      case Kind::Depth: entry.depth = builder.read<DepthMap>(entry.buffer); break;
      case Kind::Normals: entry.normals = builder.read<NormalMap>(entry.buffer); break;
    }
  }
}

void BufferPreviews::for_each(StageContext& context,
                              const std::function<void(const std::string&, const ColorImage&)>& visit) const {
  for (const Entry& entry : entries_) {
    switch (entry.kind) {
      case Kind::Color: visit(entry.buffer, context.get(entry.color)); break;
      case Kind::Depth: visit(entry.buffer, depth_preview(context.get(entry.depth))); break;
      case Kind::Normals: visit(entry.buffer, normal_preview(context.get(entry.normals))); break;
    }
  }
}

}  // namespace relight::app
