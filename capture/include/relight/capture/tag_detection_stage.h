#pragma once
// The AprilTags of each frame, detected once for every stage that needs them: the camera's
// marker pose (marker_pose.h) and a tracked lamp's own tag (app/tracked_lamp_stage.h). Each of
// them ran its own detector on the same image before; detection is the costly half of both
// (about 10 ms a frame at 640x480 on this machine).
//
// Stage TagDetectionStage ("tag_detection")
//   reads:  "color" (ColorImage)
//   writes: "tag_detections" (TagDetections): every tag36h11 tag in the image, sorted by id and
//           position (tag_detector.h). Culled when no stage reads it.
#include <vector>

#include "relight/capture/tag_detector.h"
#include "relight/core/buffer_name.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"

namespace relight::capture {

struct TagDetections {
  std::vector<TagDetection> tags;
  static constexpr const char* type_name = "TagDetections";
};

inline constexpr BufferName<TagDetections> kTagDetections{"tag_detections"};

class TagDetectionStage final : public Stage {
 public:
  explicit TagDetectionStage(const TagDetectorOptions& options = {}) : detector_(options) {}
  [[nodiscard]] std::string name() const override { return "tag_detection"; }
  void declare(StageBuilder& builder) override {
    color_ = builder.read(kColor);
    detections_ = builder.write(kTagDetections);
  }
  void run(StageContext& context) override { context.get(detections_).tags = detector_.detect(context.get(color_)); }

 private:
  TagDetector detector_;
  Read<ColorImage> color_;
  Write<TagDetections> detections_;
};

}  // namespace relight::capture
