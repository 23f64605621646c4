#include "frame_writer_stage.h"

#include <cstdio>

#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::app {

void FrameWriterStage::declare(StageBuilder& builder) {
  for (const auto& name : color_names_) colors_.push_back(builder.read<ColorImage>(name));
  for (const auto& name : depth_names_) depths_.push_back(builder.read<DepthMap>(name));
  for (const auto& name : normal_names_) normals_.push_back(builder.read<NormalMap>(name));
  for (const auto& name : radiance_names_) radiances_.push_back(builder.read<RadianceImage>(name));
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
  for (std::size_t i = 0; i < colors_.size(); ++i) {
    write_color(file_for(context.frame_index(), color_names_[i]), context.get(colors_[i]));
  }
  for (std::size_t i = 0; i < depths_.size(); ++i) {
    write_color(file_for(context.frame_index(), depth_names_[i]), depth_preview(context.get(depths_[i])));
  }
  for (std::size_t i = 0; i < normals_.size(); ++i) {
    write_color(file_for(context.frame_index(), normal_names_[i]), normal_preview(context.get(normals_[i])));
  }
  for (std::size_t i = 0; i < radiances_.size(); ++i) {
    write_radiance(file_for(context.frame_index(), radiance_names_[i], ".exr"), context.get(radiances_[i]));
  }
}

}  // namespace relight::app
