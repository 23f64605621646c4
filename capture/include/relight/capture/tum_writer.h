#pragma once
// Writes a TUM RGB-D folder: rgb/<timestamp>.png, depth/<timestamp>.png (16-bit, scale 5000 by
// default), rgb.txt, depth.txt and, when poses are given, groundtruth.txt
// ("timestamp tx ty tz qx qy qz qw", camera-to-world). Every file is written atomically; the
// list files are written by finish(), so a folder without rgb.txt is an unfinished one.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "relight/core/image.h"
#include "relight/core/pose.h"

namespace relight::capture {

class TumWriter {
 public:
  /// Creates folder, folder/rgb and folder/depth. Throws relight::Error when it cannot.
  explicit TumWriter(std::filesystem::path folder, double depth_scale = 5000.0);

  /// Adds one frame; colour and depth share the timestamp. Timestamps must increase.
  void add(Timestamp timestamp, const ColorImage& color, const DepthMap& depth,
           const std::optional<Pose>& camera_to_world = std::nullopt);
  /// Writes rgb.txt, depth.txt and groundtruth.txt (if any pose was given).
  void finish();

  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
  [[nodiscard]] std::size_t frames() const { return lines_.size(); }
  /// File name used for a timestamp, e.g. "1.033333.png" (six decimals, as TUM).
  [[nodiscard]] static std::string file_name(Timestamp timestamp);

 private:
  struct Line {
    Timestamp timestamp;
    std::optional<Pose> pose;
  };
  std::filesystem::path folder_;
  double depth_scale_;
  std::vector<Line> lines_;
};

}  // namespace relight::capture
