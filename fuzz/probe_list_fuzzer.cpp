// Fuzzes the probe list (`--probe probe.txt`, lights/probe_stream.h, open_probe_list): the input is
// the list ("timestamp filename" lines); the files it may name, a.hdr and b.hdr, exist beside it
// (tiny valid probes) and c.hdr is a broken one. relight::Error is the answer to a malformed list
// or probe; any other exception, a crash or a sanitizer report is a finding. An opened list
// must play its frames in strictly increasing time.
#include <cstdlib>
#include <optional>
#include <string>

#include "fuzz_input.h"
#include "image_size_limit.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/lights/probe_stream.h"

namespace {

// A 2x1 Radiance HDR with flat (not run-length encoded) pixels.
std::string tiny_probe() {
  std::string file = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  file += std::string("\x80\x80\x80\x81\x40\x40\x40\x80", 8);
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& scratch = relight::fuzz::scratch();
  static const bool probes_written = [&] {
    scratch.write("a.hdr", tiny_probe());
    scratch.write("b.hdr", tiny_probe());
    scratch.write("c.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 9 +X 9\n\x02");
    return true;
  }();
  (void)probes_written;
  const auto list = scratch.write("probe.txt", relight::fuzz::as_text(data, size));
  try {
    const auto stream = relight::lights::open_probe_list(list, {});
    std::optional<double> last;
    for (int frames = 0; frames < 64; ++frames) {
      const auto next = stream->next_timestamp();
      if (!next) break;
      if (last && !(*next > *last)) std::abort();
      last = next;
      stream->advance();
      try {
        (void)stream->decode();
      } catch (const relight::Error&) {
      }
    }
  } catch (const relight::Error&) {
  }
  return 0;
}
