#pragma once
// Outputs are written atomically: the bytes go to a temporary file in the destination folder,
// which is flushed and then renamed over the target. A crash or a failed write never leaves a
// half-written output behind, and readers never see a partial file.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string_view>

namespace relight {

/// Write bytes to path atomically (temp file + fsync + rename). Throws relight::Error naming the
/// path on failure; the temporary file is removed in that case.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);
void write_file_atomically(const std::filesystem::path& path, std::string_view text);

/// Read a whole file; throws relight::Error naming the path when it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

}  // namespace relight
