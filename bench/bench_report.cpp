#include "bench_report.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <thread>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"

namespace relight::bench {

namespace {

std::string number(const Json& value) {
  if (!value.is_number_float()) return value.is_string() ? value.get<std::string>() : value.dump();
  const double x = value.get<double>();
  char text[32];
  std::snprintf(text, sizeof text, std::abs(x) >= 100 ? "%.0f" : std::abs(x) >= 1 ? "%.2f" : "%.3g", x);
  return text;
}

std::string cell(const Json& result, const char* key) { return result.contains(key) ? number(result[key]) : ""; }

// The fields besides the standard ones, as "name value" pairs (nested objects get their own table).
std::string quality_fields(const Json& result) {
  std::string text;
  for (const auto& [key, value] : result.items()) {
    if (key == "case" || key == "ms" || key == "baseline" || key == "baseline_ms" || key == "ratio") continue;
    if (value.is_object() || value.is_array()) continue;
    std::string shown = number(value);
    for (char& c : shown) c = c == '|' ? '/' : c;
    text += (text.empty() ? "" : ", ") + key + " " + shown;
  }
  return text;
}

std::string timestamp() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return text;
}

}  // namespace

std::string markdown_report(const std::vector<Json>& results, const std::string& machine) {
  std::ostringstream md;
  md << "# relight-bench results\n\n" << machine << "\n\n";
  md << "| case | ms (median) | baseline | baseline ms | ratio (baseline/ours) | other fields |\n";
  md << "|---|---:|---|---:|---:|---|\n";
  for (const auto& result : results) {
    md << "| " << cell(result, "case") << " | " << cell(result, "ms") << " | " << cell(result, "baseline") << " | "
       << cell(result, "baseline_ms") << " | " << cell(result, "ratio") << " | "
       << (result.contains("error") ? "**error:** " + result["error"].get<std::string>() : quality_fields(result))
       << " |\n";
  }
  for (const auto& result : results) {
    for (const auto& [key, value] : result.items()) {
      if (!value.is_object()) continue;
      md << "\n## " << cell(result, "case") << ": " << key << "\n\n| stage | value |\n|---|---:|\n";
      for (const auto& [stage, entry] : value.items()) md << "| " << stage << " | " << number(entry) << " |\n";
    }
  }
  return md.str();
}

void write_report(const std::filesystem::path& folder, const std::vector<Json>& results) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw Error("cannot create " + folder.string() + ": " + ec.message());
  char host[256] = "unknown";
  ::gethostname(host, sizeof host - 1);
  const std::string machine = "Measured " + timestamp() + " on " + host + " (" +
                              std::to_string(std::thread::hardware_concurrency()) + " hardware threads).";
  Json all = Json::object();
  all["machine"] = machine;
  all["results"] = results;
  write_file_atomically(folder / "bench.json", all.dump(2) + "\n");
  write_file_atomically(folder / "bench.md", markdown_report(results, machine));
}

}  // namespace relight::bench
