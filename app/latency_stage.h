#pragma once
// Sink stage: how long after its capture each frame's final picture is ready - the latency a
// viewer of the live composite sees (capture to composite; without rendering, to the normals,
// the last geometry stage). The clock starts at FrameInfo::capture_time: for a live device its
// timestamp mapped onto the host clock (so the time a frame waited for a busy pipeline counts),
// for a recording the moment the source read it.
//
// Reads: "source_frame" (FrameInfo), and the end buffer (ColorImage composite, or NormalMap
//        "normals"), which orders the stage after everything that picture depends on.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/rgbd_frame.h"

namespace relight::app {

class LatencyStage final : public Stage {
 public:
  /// `composite`: the ColorImage whose readiness ends the latency; none: the normals.
  explicit LatencyStage(std::optional<BufferName<ColorImage>> composite) : composite_(composite) {}
  [[nodiscard]] std::string name() const override { return "latency"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

  /// {"to": buffer, "frames", "median_ms", "p95_ms", "max_ms"} for report.json.
  [[nodiscard]] nlohmann::ordered_json summary() const;
  /// The last frame's latency in milliseconds (0 before the first frame).
  [[nodiscard]] double last_ms() const { return latencies_ms_.empty() ? 0.0 : latencies_ms_.back(); }

 private:
  std::optional<BufferName<ColorImage>> composite_;
  std::vector<double> latencies_ms_;
  Read<FrameInfo> frame_;
  Read<ColorImage> picture_;
  Read<NormalMap> normals_;
};

}  // namespace relight::app
