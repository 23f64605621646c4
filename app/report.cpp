#include "report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>

#include <sys/resource.h>

#include "html_report.h"
#include "relight/core/atomic_file.h"
#include "report_collector_stage.h"

namespace relight::app {

MsSummary summarize(std::vector<double> ms) {
  MsSummary summary;
  if (ms.empty()) return summary;
  std::sort(ms.begin(), ms.end());
  const std::size_t n = ms.size();
  summary.median = n % 2 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  summary.mean = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(n);
  summary.p95 = ms[std::min(n - 1, static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n))) - 1)];
  summary.max = ms.back();
  return summary;
}

nlohmann::ordered_json timing_report(const FrameGraph& graph, double total_seconds) {
  nlohmann::ordered_json report;
  report["frames"] = graph.frames_run();
  report["seconds"] = total_seconds;
  report["fps"] = total_seconds > 0 ? static_cast<double>(graph.frames_run()) / total_seconds : 0.0;
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) == 0) report["peak_rss_mb"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
  // Open at the end of the run (the outputs being written are closed by then): a count that grows
  // with the run's length is a leak (scripts/soak.sh compares 1 000 and 10 000 frames).
  std::error_code ec;
  std::int64_t descriptors = 0;
  for (auto it = std::filesystem::directory_iterator("/proc/self/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    ++descriptors;
  }
  if (!ec) report["open_file_descriptors"] = descriptors - 1;  // less the one the listing holds
  report["execution_order"] = graph.execution_order();
  report["culled_stages"] = graph.culled_stages();
  auto& stages = report["stages"] = nlohmann::ordered_json::array();
  for (const auto& timing : graph.timings()) {
    const MsSummary wall = summarize(timing.wall_ms);
    nlohmann::ordered_json stage;
    stage["stage"] = timing.stage;
    stage["backend"] = to_string(timing.backend);
    stage["buffers"] = timing.device_buffers ? "device" : "host";
    stage["frames"] = timing.wall_ms.size();
    stage["median_ms"] = wall.median;
    stage["mean_ms"] = wall.mean;
    stage["p95_ms"] = wall.p95;
    stage["max_ms"] = wall.max;
    if (!timing.device_ms.empty()) stage["device_median_ms"] = summarize(timing.device_ms).median;
    // The process's CPU time while the stage ran; over median_ms, the cores it kept busy (what
    // report.html's timing table shows).
    if (!timing.cpu_ms.empty()) stage["cpu_median_ms"] = summarize(timing.cpu_ms).median;
    stage["wall_ms"] = timing.wall_ms;
    if (!timing.device_ms.empty()) stage["device_ms"] = timing.device_ms;
    stages.push_back(std::move(stage));
  }
  return report;
}

void write_reports(const std::filesystem::path& folder, const std::string& title, const FrameGraph& graph,
                   const nlohmann::ordered_json& report, const ReportCollectorStage* collector) {
  write_file_atomically(folder / "report.json", report.dump(2) + "\n");
  const std::string dot = graph.to_dot();
  const ReportContent content = collector ? collector->content() : ReportContent{};
  write_file_atomically(folder / "report.html", html_report(title, report, content, dot, render_dot_svg(dot)));
}

}  // namespace relight::app
