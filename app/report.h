#pragma once
// report.json of a run: what ran, in which order, and how long each stage took per frame
// (median/mean/p95/max wall time, GPU time where measured, and the per-frame series).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "relight/core/frame_graph.h"

namespace relight::app {

[[nodiscard]] nlohmann::ordered_json timing_report(const FrameGraph& graph, double total_seconds);

class ReportCollectorStage;

/// Writes DIR/report.json (`report`) and DIR/report.html (the same plus what `collector` gathered,
/// and the graph drawn by Graphviz when it is installed), each atomically.
void write_reports(const std::filesystem::path& folder, const std::string& title, const FrameGraph& graph,
                   const nlohmann::ordered_json& report, const ReportCollectorStage* collector);

/// Summary statistics of a series of milliseconds.
struct MsSummary {
  double median = 0, mean = 0, p95 = 0, max = 0;
};
[[nodiscard]] MsSummary summarize(std::vector<double> ms);

}  // namespace relight::app
