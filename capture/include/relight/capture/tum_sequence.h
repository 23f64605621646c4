#pragma once
// Reader for TUM RGB-D folders (Sturm et al., IROS 2012): rgb.txt, depth.txt and optionally
// groundtruth.txt ("timestamp tx ty tz qx qy qz qw", camera-to-world), images under rgb/ and
// depth/ (16-bit PNG, metres = value / depth_scale, 5000 in TUM).
//
// Colour and depth are associated as TUM's associate.py does: all pairs closer than
// max_time_difference (0.02 s) are candidates, taken greedily from the closest, each image used
// once. Ground-truth poses are interpolated at the depth timestamp (linear + slerp) between the
// two bracketing entries; frames outside the ground-truth time range get no pose.
//
// Intrinsics, first that applies: TumOptions::intrinsics, "intrinsics" in scene.json beside the
// lists (relight synth writes it), Kinect v1 / ROS defaults - also for the Freiburg folders,
// whose depth the OpenNI driver registered to colour with the factory model (TUM recommends
// these defaults for it; the calibrated colour cameras are the fr1/fr2/fr3 presets, on request).
//
// Every problem (missing folder or list, malformed or unsorted line, missing/corrupt/8-bit image,
// a depth image without one valid pixel) throws relight::Error naming the file and line.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "relight/capture/frame_source.h"
#include "relight/core/camera.h"
#include "relight/core/pose.h"

namespace relight::capture {

struct TumOptions {
  double max_time_difference = 0.02;           ///< seconds, as TUM's associate.py
  std::optional<PinholeIntrinsics> intrinsics;  ///< overrides scene.json / folder presets
  std::optional<double> depth_scale;           ///< overrides scene.json (default 5000)
};

struct TumEntry {
  Timestamp timestamp = 0;
  std::filesystem::path file;  ///< relative to the folder
};

/// One associated colour/depth pair.
struct TumFrame {
  Timestamp depth_timestamp = 0;
  Timestamp color_timestamp = 0;
  std::filesystem::path depth_file;  ///< absolute
  std::filesystem::path color_file;  ///< absolute
  std::optional<Pose> camera_to_world;
};

/// Parses a TUM list ("timestamp filename" per line, '#' comments). Throws naming file:line.
std::vector<TumEntry> read_tum_list(const std::filesystem::path& list_file);
/// Parses groundtruth.txt into (timestamp, pose) pairs. Throws naming file:line.
std::vector<std::pair<Timestamp, Pose>> read_tum_trajectory(const std::filesystem::path& file);
/// Greedy nearest-timestamp association; returns index pairs (first, second) sorted by first.
std::vector<std::pair<std::size_t, std::size_t>> associate(const std::vector<TumEntry>& first,
                                                           const std::vector<TumEntry>& second,
                                                           double max_difference);
/// Pose at time t by interpolation; nullopt outside the trajectory's time range.
std::optional<Pose> pose_at(const std::vector<std::pair<Timestamp, Pose>>& trajectory, Timestamp t);

class TumSequence {
 public:
  static TumSequence open(const std::filesystem::path& folder, const TumOptions& options = {});

  [[nodiscard]] std::size_t size() const { return frames_.size(); }
  [[nodiscard]] const TumFrame& frame(std::size_t i) const { return frames_.at(i); }
  [[nodiscard]] RgbdFrame load(std::size_t i) const;
  [[nodiscard]] const PinholeIntrinsics& intrinsics() const { return intrinsics_; }
  [[nodiscard]] const std::string& intrinsics_source() const { return intrinsics_source_; }
  [[nodiscard]] double depth_scale() const { return depth_scale_; }
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_;
  std::vector<TumFrame> frames_;
  PinholeIntrinsics intrinsics_;
  std::string intrinsics_source_;
  double depth_scale_ = 5000.0;
};

/// FrameSource over a TumSequence, optionally restricted to frames [first, last).
class TumSource final : public FrameSource {
 public:
  TumSource(TumSequence sequence, std::size_t first = 0, std::optional<std::size_t> last = std::nullopt);
  [[nodiscard]] std::optional<RgbdFrame> next() override;
  [[nodiscard]] std::int64_t size_hint() const override { return static_cast<std::int64_t>(last_ - first_); }
  [[nodiscard]] std::string describe() const override;
  /// With a handler, a frame that cannot be read (missing or corrupt image) is reported to it with
  /// its index in the folder and skipped; without one (the default) it throws relight::Error.
  void on_bad_frame(std::function<void(std::size_t index, const std::string& message)> handler) {
    on_bad_frame_ = std::move(handler);
  }

 private:
  std::function<void(std::size_t, const std::string&)> on_bad_frame_;
  TumSequence sequence_;
  std::size_t first_;
  std::size_t last_;
  std::size_t next_;
};

}  // namespace relight::capture
