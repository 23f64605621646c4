#include "buffer_previews.h"

#include <algorithm>
#include <cmath>

#include "relight/core/image_io.h"

namespace relight::app {

namespace {

ColorImage coverage_preview(const render::CoverageImage& coverage) {
  ColorImage out(coverage.width(), coverage.height());
  for (std::size_t i = 0; i < out.pixels().size(); ++i) {
    const auto grey = static_cast<std::uint8_t>(std::lround(255.f * std::clamp(coverage.pixels()[i], 0.f, 1.f)));
    out.pixels()[i] = Rgb8{grey, grey, grey};
  }
  return out;
}

}  // namespace

void BufferPreviews::declare(StageBuilder& builder) {
  for (Entry& entry : entries_) {
    switch (entry.kind) {
      case Kind::Color: entry.color = builder.read<ColorImage>(entry.buffer); break;
      case Kind::Depth: entry.depth = builder.read<DepthMap>(entry.buffer); break;
      case Kind::Normals: entry.normals = builder.read<NormalMap>(entry.buffer); break;
      case Kind::Coverage: entry.coverage = builder.read<render::CoverageImage>(entry.buffer); break;
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
      case Kind::Coverage: visit(entry.buffer, coverage_preview(context.get(entry.coverage))); break;
    }
  }
}

}  // namespace relight::app
