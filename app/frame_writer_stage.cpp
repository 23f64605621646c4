#include "frame_writer_stage.h"

#include <cstdio>

#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::app {

void FrameWriterStage::declare(StageBuilder& builder) {
  previews_.declare(builder);
  for (const auto name : radiance_names_) radiances_.push_back(builder.read(name));
}

std::filesystem::path FrameWriterStage::file_for(std::int64_t frame, const std::string& buffer,
                                                 const char* extension) const {
  char name[64];
  std::snprintf(name, sizeof name, "%06lld_", static_cast<long long>(frame));
  return folder_ / (name + buffer + extension);
}

void FrameWriterStage::run(StageContext& context) {
  if (context.frame_index() == 0) {
    std::error_code ec;
    std::filesystem::create_directories(folder_, ec);
    if (ec) throw Error("cannot create " + folder_.string() + ": " + ec.message());
  }
  // Copies: the graph reuses its buffers for the next frame while the queue writes these.
  previews_.for_each(context, [&](const std::string& buffer, const ColorImage& picture) {
    queue_.push([path = file_for(context.frame_index(), buffer), picture] { write_color(path, picture); });
  });
  for (std::size_t i = 0; i < radiances_.size(); ++i) {
    queue_.push([path = file_for(context.frame_index(), std::string(radiance_names_[i].name()), ".exr"),
                 image = context.get(radiances_[i])] { write_radiance(path, image); });
  }
}

}  // namespace relight::app
