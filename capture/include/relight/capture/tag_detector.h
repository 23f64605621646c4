#pragma once
// AprilTag tag36h11 detection with the AprilRobotics apriltag library (Debian libapriltag-dev),
// kept behind this interface so that its C headers do not leak into the rest of relight.
#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "relight/core/image.h"

namespace relight::capture {

struct TagDetection {
  int id = 0;
  /// Black-square corners in pixels (u = column, v = row, pixel centres at integers, as in
  /// PinholeIntrinsics; apriltag's own +0.5 convention is converted), in
  /// AprilTag's order: counter-clockwise in the image starting at tag-frame (-s/2, +s/2).
  std::array<Eigen::Vector2d, 4> corners{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                        Eigen::Vector2d::Zero()};
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double decision_margin = 0;  ///< apriltag's confidence; low values are weak detections
  int hamming = 0;             ///< corrected bit errors
};

struct TagDetectorOptions {
  float decimate = 1.0f;      ///< quad_decimate: 2 is faster and less precise on small tags
  /// apriltag's worker threads; 0: default_tag_detector_threads() (the detections do not depend on
  /// it: they are sorted by id and position).
  int threads = 0;
  bool refine_edges = true;
  int max_hamming = 1;        ///< detections with more corrected bits are dropped
};

class TagDetector {
 public:
  explicit TagDetector(const TagDetectorOptions& options = {});
  ~TagDetector();
  TagDetector(TagDetector&&) noexcept;
  TagDetector& operator=(TagDetector&&) noexcept;
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  /// Detections in the colour image (converted to grey), sorted by id then position.
  [[nodiscard]] std::vector<TagDetection> detect(const ColorImage& image);
  [[nodiscard]] std::vector<TagDetection> detect(const Image<std::uint8_t>& grey);

 private:
  struct Library;
  std::unique_ptr<Library> library_;
  TagDetectorOptions options_;
};

/// One per hardware thread, but one on a machine with two or fewer: there apriltag's worker pool
/// costs more than it shares (bench apriltag/detect_640x480 on two cores: 4.2-4.3 ms on two
/// threads, 3.3-3.4 on one; the replay's tag_detection stage 9.3-10.3 ms against 6.7-8.2).
[[nodiscard]] int default_tag_detector_threads();

/// Rec. 601 luma of an sRGB image, as 8-bit grey.
[[nodiscard]] Image<std::uint8_t> to_grey(const ColorImage& image);

}  // namespace relight::capture
