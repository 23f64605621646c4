#pragma once
// Binary glTF files made in tests.
#include <string>

namespace relight::test {

// A binary glTF container: 12-byte header, JSON chunk (padded with spaces), BIN chunk.
inline std::string glb(std::string json, const std::string& bin) {
  while (json.size() % 4 != 0) json += ' ';
  const auto u32 = [](std::size_t v) {
    std::string bytes(4, '\0');
    for (int i = 0; i < 4; ++i) bytes[static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xffu);
    return bytes;
  };
  const std::string body = u32(json.size()) + "JSON" + json + u32(bin.size()) + std::string("BIN\0", 4) + bin;
  return "glTF" + u32(2) + u32(12 + body.size()) + body;
}

}  // namespace relight::test
