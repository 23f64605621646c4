#include "relight/capture/tum_writer.h"

#include <cstdio>
#include <sstream>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::capture {

TumWriter::TumWriter(std::filesystem::path folder, double depth_scale)
    : folder_(std::move(folder)), depth_scale_(depth_scale) {
  std::error_code ec;
  for (const char* sub : {"rgb", "depth"}) {
    std::filesystem::create_directories(folder_ / sub, ec);
    if (ec) throw Error("cannot create " + (folder_ / sub).string() + ": " + ec.message());
  }
}

std::string TumWriter::file_name(Timestamp timestamp) {
  char name[64];
  std::snprintf(name, sizeof name, "%.6f.png", timestamp);
  return name;
}

void TumWriter::add(Timestamp timestamp, const ColorImage& color, const DepthMap& depth,
                    const std::optional<Pose>& camera_to_world) {
  if (!lines_.empty() && timestamp <= lines_.back().timestamp) {
    throw Error("TumWriter: timestamps must increase (" + std::to_string(timestamp) + " after " +
                std::to_string(lines_.back().timestamp) + ")");
  }
  const std::string name = file_name(timestamp);
  write_color(folder_ / "rgb" / name, color);
  write_depth_png(folder_ / "depth" / name, depth, depth_scale_);
  lines_.push_back({timestamp, camera_to_world});
}

void TumWriter::finish() {
  std::ostringstream rgb, depth, groundtruth;
  rgb << "# color images\n# timestamp filename\n";
  depth << "# depth maps (scale " << depth_scale_ << ")\n# timestamp filename\n";
  groundtruth << "# ground truth trajectory (camera to world)\n# timestamp tx ty tz qx qy qz qw\n";
  bool any_pose = false;
  char buffer[256];
  for (const auto& line : lines_) {
    const std::string name = file_name(line.timestamp);
    std::snprintf(buffer, sizeof buffer, "%.6f", line.timestamp);
    rgb << buffer << " rgb/" << name << '\n';
    depth << buffer << " depth/" << name << '\n';
    if (line.pose) {
      any_pose = true;
      const auto f = pose_to_tum(*line.pose);
      std::snprintf(buffer, sizeof buffer, "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", line.timestamp, f[0], f[1],
                    f[2], f[3], f[4], f[5], f[6]);
      groundtruth << buffer;
    }
  }
  write_file_atomically(folder_ / "depth.txt", depth.str());
  if (any_pose) write_file_atomically(folder_ / "groundtruth.txt", groundtruth.str());
  // rgb.txt last: its presence marks a finished folder.
  write_file_atomically(folder_ / "rgb.txt", rgb.str());
}

}  // namespace relight::capture
