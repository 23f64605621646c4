#pragma once
// What every row of the robustness matrix asserts about a run of relight (bounded_run.h):
//  - it ended by itself within its time limit, with an exit code, not killed by a signal;
//  - a failure printed exactly one line, "relight: error: ...", naming the input at fault;
//  - the output folder holds no unfinished file: no temporary (*.tmp-*, *.partial*) and no
//    PNG / EXR / HDR / JSON / MP4 / ONI that does not read back completely.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "bounded_run.h"
#include "relight/capture/openni_source.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::robustness {

inline std::size_t count_lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

inline std::size_t count_lines_starting(const std::string& text, const std::string& prefix) {
  std::size_t count = 0;
  for (std::size_t at = 0; at < text.size();) {
    if (text.compare(at, prefix.size(), prefix) == 0) ++count;
    const auto end = text.find('\n', at);
    if (end == std::string::npos) break;
    at = end + 1;
  }
  return count;
}

/// Why `file` is not a complete output, or "" when it reads back.
inline std::string why_unfinished(const std::filesystem::path& file) {
  const std::string name = file.filename().string();
  if (name.find(".tmp-") != std::string::npos || name.find(".partial") != std::string::npos) return "temporary file";
  const std::string ext = file.extension().string();
  try {
    if (ext == ".png" && cv::imread(file.string(), cv::IMREAD_UNCHANGED).empty()) return "PNG does not decode";
    if (ext == ".exr" || ext == ".hdr") (void)read_radiance(file);
    if (ext == ".json" && !nlohmann::json::accept(read_text_file(file))) return "JSON does not parse";
    if (ext == ".oni" && capture::inspect_oni(file).depth_frames < 1) return "recording without frames";
    if (ext == ".mp4") {
      cv::VideoCapture video(file.string());
      cv::Mat frame;
      if (!video.isOpened() || !video.read(frame) || frame.empty()) return "video does not decode";
    }
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

/// "path: why" for every unfinished file under `folder` (none when it does not exist).
inline std::vector<std::string> unfinished_outputs(const std::filesystem::path& folder) {
  std::vector<std::string> found;
  std::error_code ec;
  if (!std::filesystem::exists(folder, ec)) return found;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    if (const std::string why = why_unfinished(entry.path()); !why.empty()) found.push_back(entry.path().string() + ": " + why);
  }
  return found;
}

inline std::string describe(const RunOutcome& run) {
  return "exit " + std::to_string(run.exit_code) + ", signal " + std::to_string(run.signal) +
         (run.timed_out ? ", timed out" : "") + ", " + std::to_string(run.seconds) + " s\nstderr:\n" + run.err;
}

/// Ended by itself with an exit code (no signal, no time-out).
inline void expect_no_crash_or_hang(const RunOutcome& run) {
  EXPECT_FALSE(run.timed_out) << describe(run);
  EXPECT_EQ(run.signal, 0) << describe(run);
}

/// The bad-input contract: `exit_code`, one line "relight: error: ..." containing `names`, and
/// nothing unfinished under `out`.
inline void expect_clean_error(const RunOutcome& run, int exit_code, const std::string& names,
                               const std::filesystem::path& out) {
  expect_no_crash_or_hang(run);
  EXPECT_EQ(run.exit_code, exit_code) << describe(run);
  EXPECT_EQ(run.err.rfind("relight: error: ", 0), 0u) << describe(run);
  EXPECT_EQ(count_lines(run.err), 1u) << describe(run);
  EXPECT_NE(run.err.find(names), std::string::npos) << "the error should name " << names << "\n" << describe(run);
  const auto unfinished = unfinished_outputs(out);
  EXPECT_TRUE(unfinished.empty()) << unfinished.front();
}

/// Peak memory of a run refusing a huge input: a normal replay of the sample peaks at about 320 MB
/// here (500 MB rendering), a 30 000 x 30 000 image would take 2.7 GB decoded as 8-bit RGB.
inline constexpr double kBoundedPeakMb = 1024.0;

/// The run stayed within kBoundedPeakMb (the input was refused before anything was allocated for it).
inline void expect_bounded_memory(const RunOutcome& run) {
  EXPECT_GT(run.peak_rss_mb, 0.0) << describe(run);
  EXPECT_LT(run.peak_rss_mb, kBoundedPeakMb) << describe(run);
}

/// Success with nothing unfinished under `out`.
inline void expect_clean_success(const RunOutcome& run, const std::filesystem::path& out) {
  expect_no_crash_or_hang(run);
  EXPECT_EQ(run.exit_code, 0) << describe(run);
  const auto unfinished = unfinished_outputs(out);
  EXPECT_TRUE(unfinished.empty()) << unfinished.front();
}

}  // namespace relight::robustness
