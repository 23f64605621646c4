#include "latency_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace relight::app {

void LatencyStage::declare(StageBuilder& builder) {
  frame_ = builder.read(kSourceFrame);
  if (composite_) {
    picture_ = builder.read(*composite_);
  } else {
    normals_ = builder.read(kNormals);
  }
}

void LatencyStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  if (frame.capture_time == 0.0) return;  // a source that does not say when it captured
  const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  latencies_ms_.push_back(std::max(0.0, 1000.0 * (now - frame.capture_time)));
}

nlohmann::ordered_json LatencyStage::summary() const {
  nlohmann::ordered_json out;
  out["to"] = composite_ ? composite_->name() : kNormals.name();
  out["frames"] = latencies_ms_.size();
  if (latencies_ms_.empty()) return out;
  std::vector<double> sorted = latencies_ms_;
  std::sort(sorted.begin(), sorted.end());
  const auto at = [&sorted](double share) {
    return sorted[static_cast<std::size_t>(std::lround(share * static_cast<double>(sorted.size() - 1)))];
  };
  out["median_ms"] = at(0.5);
  out["p95_ms"] = at(0.95);
  out["max_ms"] = sorted.back();
  return out;
}

}  // namespace relight::app
