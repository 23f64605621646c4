// relight-bench [--list] [--repetitions N] [--report DIR] [FILTER]: runs the cases whose name
// contains FILTER, or only the case named FILTER when one is.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <exception>
#include <iostream>

#include "bench.h"
#include "bench_report.h"
#include "relight/core/allocator_tuning.h"

int main(int argc, char** argv) {
  relight::keep_freed_memory_for_reuse();
  CLI::App app{"relight-bench: speed and quality of relight's stages against their baselines.\n"
               "Prints one JSON object per line per case."};
  bool list = false;
  std::string filter;
  relight::bench::Options options;
  app.add_flag("--list", list, "List the case names and exit");
  app.add_option("--repetitions", options.repetitions, "Timed repetitions per side")->check(CLI::Range(1, 1000));
  std::string report;
  app.add_option("--report", report, "Also write DIR/bench.json and DIR/bench.md (a Markdown table) of the results");
  app.add_option("filter", filter, "Run only cases whose name contains this text");
  CLI11_PARSE(app, argc, argv);

  int matched = 0;
  std::vector<relight::bench::Json> results;
  // A filter that names a case exactly runs that case alone (pipeline/replay_640x480 is also the
  // start of other cases' names).
  const auto& cases = relight::bench::cases();
  const bool exact = std::any_of(cases.begin(), cases.end(), [&](const auto& c) { return c.name == filter; });
  for (const auto& bench_case : cases) {
    if (exact ? bench_case.name != filter : bench_case.name.find(filter) == std::string::npos) continue;
    ++matched;
    if (list) {
      std::cout << bench_case.name << '\n';
      continue;
    }
    relight::bench::Json line;
    line["case"] = bench_case.name;
    try {
      line.update(bench_case.run(options));
    } catch (const std::exception& e) {
      line["error"] = e.what();
    }
    std::cout << line.dump() << std::endl;
    results.push_back(std::move(line));
  }
  if (matched == 0) {
    std::cerr << "relight-bench: no case matches '" << filter << "' (see --list)\n";
    return 2;
  }
  if (!report.empty() && !list) {
    try {
      relight::bench::write_report(report, results);
    } catch (const std::exception& e) {
      std::cerr << "relight-bench: error: " << e.what() << "\n";
      return 1;
    }
  }
  return 0;
}
