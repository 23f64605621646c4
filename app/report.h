#pragma once
// report.json of a run: what ran, in which order, and how long each stage took per frame
// (median/mean/p95/max wall time, GPU time where measured, and the per-frame series).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "relight/core/frame_graph.h"

namespace relight::app {

[[nodiscard]] nlohmann::ordered_json timing_report(const FrameGraph& graph, double total_seconds);

/// Summary statistics of a series of milliseconds.
struct MsSummary {
  double median = 0, mean = 0, p95 = 0, max = 0;
};
[[nodiscard]] MsSummary summarize(std::vector<double> ms);

}  // namespace relight::app
