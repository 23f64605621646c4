#include "relight/capture/tag_detector.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "relight/core/error.h"

namespace relight::capture {

// The apriltag C objects, released in the right order (detector before its family).
struct TagDetector::Library {
  struct FamilyDeleter {
    void operator()(apriltag_family_t* family) const { tag36h11_destroy(family); }
  };
  struct DetectorDeleter {
    void operator()(apriltag_detector_t* detector) const { apriltag_detector_destroy(detector); }
  };
  std::unique_ptr<apriltag_family_t, FamilyDeleter> family{tag36h11_create()};
  std::unique_ptr<apriltag_detector_t, DetectorDeleter> detector{apriltag_detector_create()};
};

namespace {
struct DetectionsDeleter {
  void operator()(zarray_t* detections) const { apriltag_detections_destroy(detections); }
};
}  // namespace

TagDetector::TagDetector(const TagDetectorOptions& options)
    : library_(std::make_unique<Library>()), options_(options) {
  if (!library_->family || !library_->detector) throw Error("cannot create the AprilTag detector");
  // Correcting up to 2 bits is what apriltag_detector_add_family does; fewer bits cost less memory.
  apriltag_detector_add_family_bits(library_->detector.get(), library_->family.get(),
                                    std::clamp(options.max_hamming, 0, 2));
  library_->detector->quad_decimate = options.decimate;
  library_->detector->nthreads = options.threads > 0 ? options.threads : default_tag_detector_threads();
  library_->detector->refine_edges = options.refine_edges;
}

int default_tag_detector_threads() {
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware <= 2 ? 1 : static_cast<int>(hardware);
}

TagDetector::~TagDetector() = default;
TagDetector::TagDetector(TagDetector&&) noexcept = default;
TagDetector& TagDetector::operator=(TagDetector&&) noexcept = default;

Image<std::uint8_t> to_grey(const ColorImage& image) {
  Image<std::uint8_t> grey(image.width(), image.height());
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Rgb8 p = image.pixels()[i];
    grey.pixels()[i] = static_cast<std::uint8_t>((299 * p.r + 587 * p.g + 114 * p.b + 500) / 1000);
  }
  return grey;
}

std::vector<TagDetection> TagDetector::detect(const ColorImage& image) { return detect(to_grey(image)); }

std::vector<TagDetection> TagDetector::detect(const Image<std::uint8_t>& grey) {
  if (grey.empty()) return {};
  // apriltag takes a non-const buffer but does not write to the input image.
  image_u8_t view{grey.width(), grey.height(), grey.width(), const_cast<std::uint8_t*>(grey.data())};
  const std::unique_ptr<zarray_t, DetectionsDeleter> found(apriltag_detector_detect(library_->detector.get(), &view));
  std::vector<TagDetection> detections;
  for (int i = 0; i < zarray_size(found.get()); ++i) {
    apriltag_detection_t* raw = nullptr;
    zarray_get(found.get(), i, &raw);
    if (raw->hamming > options_.max_hamming) continue;
    TagDetection detection;
    detection.id = raw->id;
    detection.hamming = raw->hamming;
    detection.decision_margin = raw->decision_margin;
    // apriltag puts pixel centres at +0.5 (a pixel covers [i, i+1]); relight's cameras put them at
    // integers (cx = 319.5 is the centre of a 640-wide image), so shift by half a pixel.
    detection.centre = {raw->c[0] - 0.5, raw->c[1] - 0.5};
    for (int k = 0; k < 4; ++k) {
      detection.corners[static_cast<std::size_t>(k)] = {raw->p[k][0] - 0.5, raw->p[k][1] - 0.5};
    }
    detections.push_back(detection);
  }
  std::sort(detections.begin(), detections.end(), [](const TagDetection& a, const TagDetection& b) {
    if (a.id != b.id) return a.id < b.id;
    return std::tie(a.centre.y(), a.centre.x()) < std::tie(b.centre.y(), b.centre.x());
  });
  return detections;
}

}  // namespace relight::capture
