#pragma once
// relight-bench: one runner for every speed goal. Each case prints one JSON object per line:
//   {"case": "normals/method1_cpu", "ms": <median>, "baseline": "pcl_integral_image",
//    "baseline_ms": <median>, "ratio": <baseline_ms / ms>, ...quality fields}
// Ours and the baseline run in the same process, interleaved, several repetitions, and the
// medians are reported, because this machine is noisy.
//
// Add a case in bench/cases/<stage>.cpp (picked up by CMake automatically):
//   RELIGHT_BENCH_CASE("vk/box3x3_vs_cpu", [](const relight::bench::Options& o) { ...; return json; });
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace relight::bench {

using Json = nlohmann::ordered_json;

struct Options {
  int repetitions = 7;  ///< timed repetitions per side (after one warm-up run)
};

using CaseFunction = std::function<Json(const Options&)>;

struct Case {
  std::string name;
  CaseFunction run;
};

/// Registers a case; used through RELIGHT_BENCH_CASE at namespace scope.
bool register_case(std::string name, CaseFunction run);
[[nodiscard]] const std::vector<Case>& cases();

/// Median wall time (ms) of `repetitions` runs of `work` after one warm-up run.
[[nodiscard]] double median_ms(const std::function<void()>& work, int repetitions);

struct Comparison {
  double ms = 0;           ///< median of ours
  double baseline_ms = 0;  ///< median of the baseline
};
/// Runs ours and the baseline alternately (A B A B ...), one warm-up each, and returns medians.
[[nodiscard]] Comparison compare_interleaved(const std::function<void()>& ours, const std::function<void()>& baseline,
                                             int repetitions);

/// The standard fields of a comparison case: ms, baseline, baseline_ms, ratio.
[[nodiscard]] Json comparison_json(const Comparison& comparison, const std::string& baseline_name);

}  // namespace relight::bench

#define RELIGHT_BENCH_CONCAT_INNER(a, b) a##b
#define RELIGHT_BENCH_CONCAT(a, b) RELIGHT_BENCH_CONCAT_INNER(a, b)
#define RELIGHT_BENCH_CASE(name, ...) \
  static const bool RELIGHT_BENCH_CONCAT(relight_bench_case_, __LINE__) = ::relight::bench::register_case(name, __VA_ARGS__)
