#pragma once
// The good inputs that the robustness rows break: a copy of the committed TUM slice (4 frames,
// 640x480), a small synthetic sequence made once per test run, and file surgery on them.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "bounded_run.h"
#include "relight/core/atomic_file.h"
#include "temp_dir.h"

namespace relight::robustness {

inline const std::filesystem::path kData = RELIGHT_TEST_DATA;

/// data/tum_fr1_rpy copied to `folder` (which must not exist yet).
inline std::filesystem::path copy_of_sample(const std::filesystem::path& folder) {
  std::filesystem::copy(kData / "tum_fr1_rpy", folder, std::filesystem::copy_options::recursive);
  return folder;
}

/// The sample's frame files in list order (rgb/... or depth/...).
inline std::vector<std::filesystem::path> sample_files(const std::filesystem::path& folder, const std::string& kind) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder / kind)) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

/// A 2-frame `relight synth` sequence (static camera, exact depth, with probe.hdr, scene.json and
/// its AprilTag), made once; tests copy it before changing anything.
inline const std::filesystem::path& synthetic_sequence() {
  static test::TempDir dir;
  static const std::filesystem::path sequence = [] {
    const auto path = dir.path() / "synth";
    const auto made = run_relight(
        {"synth", "--quiet", "--frames", "2", "--trajectory", "static", "--noise", "none", "--no-gt", "--out", path.string()});
    if (made.exit_code != 0) throw std::runtime_error("relight synth failed: " + made.err);
    return path;
  }();
  return sequence;
}

/// A 3-frame `relight synth` sequence whose key light switches on at frame 1: with its probe
/// stream (probe.txt, probe/*.hdr), made once; tests copy it before changing anything.
inline const std::filesystem::path& animated_light_sequence() {
  static test::TempDir dir;
  static const std::filesystem::path sequence = [] {
    const auto path = dir.path() / "animated";
    const auto made = run_relight({"synth", "--quiet", "--frames", "3", "--size", "320x240", "--trajectory", "static",
                                   "--noise", "none", "--no-gt", "--light-animation", "switch-on",
                                   "--light-event-frame", "1", "--out", path.string()});
    if (made.exit_code != 0) throw std::runtime_error("relight synth failed: " + made.err);
    return path;
  }();
  return sequence;
}

inline std::filesystem::path copy_of_synthetic(const std::filesystem::path& folder) {
  std::filesystem::copy(synthetic_sequence(), folder, std::filesystem::copy_options::recursive);
  return folder;
}

/// Rewrites the folder's rgb.txt, depth.txt, groundtruth.txt and probe.txt (when present) to list
/// `frames` frames at 30 fps that cycle through the images, poses and probes it has: a long
/// sequence, for interrupting a run in its middle, without more files.
inline void loop_sequence(const std::filesystem::path& folder, int frames) {
  for (const char* list : {"rgb.txt", "depth.txt", "groundtruth.txt", "probe.txt"}) {
    if (!std::filesystem::exists(folder / list)) continue;
    std::vector<std::string> payloads;  // each entry without its timestamp
    std::istringstream in(read_text_file(folder / list));
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line[0] != '#') payloads.push_back(line.substr(line.find(' ')));
    }
    std::ostringstream out;
    out << std::fixed << std::setprecision(6);
    for (int k = 0; k < frames; ++k) out << 1.0 + k / 30.0 << payloads[static_cast<std::size_t>(k) % payloads.size()] << "\n";
    write_file_atomically(folder / list, out.str());
  }
}

/// Rewrites a PNG's header to claim `width` x `height` pixels; the data stays as it was (a file of
/// a few kilobytes claiming gigabytes).
inline void claim_png_size(const std::filesystem::path& png, std::uint32_t width, std::uint32_t height) {
  std::string bytes = read_text_file(png);
  for (int i = 0; i < 4; ++i) {
    bytes[static_cast<std::size_t>(16 + i)] = static_cast<char>((width >> (24 - 8 * i)) & 0xff);  // IHDR width
    bytes[static_cast<std::size_t>(20 + i)] = static_cast<char>((height >> (24 - 8 * i)) & 0xff);
  }
  write_file_atomically(png, bytes);
}

/// Keeps the first `fraction` of the file's bytes.
inline void truncate_file(const std::filesystem::path& file, double fraction) {
  const std::string bytes = read_text_file(file);
  write_file_atomically(file, std::string_view(bytes).substr(0, static_cast<std::size_t>(bytes.size() * fraction)));
}

}  // namespace relight::robustness
