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

ColorImage preview(const DepthMap& depth) { return depth_preview(depth); }
ColorImage preview(const NormalMap& normals) { return normal_preview(normals); }
ColorImage preview(const render::CoverageImage& coverage) { return coverage_preview(coverage); }

std::string buffer_name(const PreviewBuffer& buffer) {
  return std::visit([](auto name) { return std::string(name.name()); }, buffer);
}

}  // namespace

void BufferPreviews::declare(StageBuilder& builder) {
  for (Entry& entry : entries_) std::visit([&](auto name) { entry.handle = builder.read(name); }, entry.buffer);
}

void BufferPreviews::for_each(StageContext& context,
                              const std::function<void(const std::string&, const ColorImage&)>& visit) const {
  for (const Entry& entry : entries_) {
    if (entry.frames && !entry.frames(context.frame_index())) continue;
    const std::string name = buffer_name(entry.buffer);
    std::visit(
        [&](auto handle) {
          const auto& image = context.get(handle);
          if constexpr (std::is_same_v<std::decay_t<decltype(image)>, ColorImage>) {
            visit(name, image);
          } else {
            visit(name, preview(image));
          }
        },
        entry.handle);
  }
}

}  // namespace relight::app
