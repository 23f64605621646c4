#include "bench.h"

#include <algorithm>
#include <chrono>

namespace relight::bench {

namespace {
std::vector<Case>& registry() {
  static std::vector<Case> all;
  return all;
}

double time_once(const std::function<void()>& work) {
  const auto start = std::chrono::steady_clock::now();
  work();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t mid = values.size() / 2;
  return values.size() % 2 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
}
}  // namespace

bool register_case(std::string name, CaseFunction run) {
  registry().push_back({std::move(name), std::move(run)});
  return true;
}

const std::vector<Case>& cases() { return registry(); }

double median_ms(const std::function<void()>& work, int repetitions) {
  work();
  std::vector<double> times;
  for (int i = 0; i < std::max(1, repetitions); ++i) times.push_back(time_once(work));
  return median(times);
}

Comparison compare_interleaved(const std::function<void()>& ours, const std::function<void()>& baseline,
                               int repetitions) {
  ours();
  baseline();
  std::vector<double> ours_ms, baseline_ms;
  for (int i = 0; i < std::max(1, repetitions); ++i) {
    ours_ms.push_back(time_once(ours));
    baseline_ms.push_back(time_once(baseline));
  }
  return {median(ours_ms), median(baseline_ms)};
}

Json comparison_json(const Comparison& comparison, const std::string& baseline_name) {
  Json json;
  json["ms"] = comparison.ms;
  json["baseline"] = baseline_name;
  json["baseline_ms"] = comparison.baseline_ms;
  json["ratio"] = comparison.ms > 0 ? comparison.baseline_ms / comparison.ms : 0.0;
  return json;
}

}  // namespace relight::bench
