#pragma once
// relight-bench --report DIR: all results of a run as DIR/bench.json (one array, the same objects
// the runner prints) and DIR/bench.md (a Markdown table: time, baseline, ratio and the quality
// fields of every case, then the per-stage breakdown of cases that have one, e.g.
// pipeline/replay_640x480's stages_ms).
#include <filesystem>
#include <string>
#include <vector>

#include "bench.h"

namespace relight::bench {

[[nodiscard]] std::string markdown_report(const std::vector<Json>& results, const std::string& machine);
void write_report(const std::filesystem::path& folder, const std::vector<Json>& results);

}  // namespace relight::bench
