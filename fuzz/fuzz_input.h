#pragma once
// What every fuzz target shares. The loaders under test read files, so a target writes its input
// into a scratch folder (one per process, in /dev/shm when there is one, removed at exit) and
// hands the loader the path. Inputs that stand for several files (a TUM folder, an OBJ with its
// MTL) hold them one after another, separated by a line "----".
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace relight::fuzz {

class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    const std::filesystem::path base =
        std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    std::string pattern = (base / "relight-fuzz-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed in " + base.string());
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  /// Writes `bytes` to path()/name (replacing it) and returns that path.
  std::filesystem::path write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path file = path_ / name;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw std::runtime_error("cannot write " + file.string());
    return file;
  }

  void remove(const std::string& name) const {
    std::error_code ignored;
    std::filesystem::remove(path_ / name, ignored);
  }

 private:
  std::filesystem::path path_;
};

/// One folder for the whole fuzzing process (libFuzzer calls the target millions of times).
inline const ScratchDir& scratch() {
  static const ScratchDir dir;
  return dir;
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Splits at lines that are exactly "----": "a\n----\nb" gives {"a\n", "b"}.
inline std::vector<std::string_view> split_files(std::string_view input) {
  static constexpr std::string_view kSeparator = "\n----\n";
  std::vector<std::string_view> parts;
  for (std::size_t at; (at = input.find(kSeparator)) != std::string_view::npos;) {
    parts.push_back(input.substr(0, at + 1));
    input.remove_prefix(at + kSeparator.size());
  }
  parts.push_back(input);
  return parts;
}

}  // namespace relight::fuzz
