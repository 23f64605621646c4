// Fuzzes the light-probe image reader (`--probe`, probe.txt's files, probe.hdr; lights/
// probe_stream.h, read_probe_image, through core/image_io.h's Radiance HDR and OpenEXR readers):
// the input is the probe file, written as probe.hdr or probe.exr by its first bytes (both readers
// check the signature against the name first). relight::Error is the answer to a corrupt file;
// any other exception, a crash or a sanitizer report is a finding. A decoded probe must be a
// non-empty image of finite, non-negative radiance and a clipped share within [0, 1].
#include <cmath>
#include <cstdlib>

#include "fuzz_input.h"
#include "image_size_limit.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/lights/probe_stream.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes = relight::fuzz::as_text(data, size);
  const bool exr = bytes.starts_with("v/1\x01");
  const auto file = relight::fuzz::scratch().write(exr ? "probe.exr" : "probe.hdr", bytes);
  try {
    const relight::lights::ProbeFrame frame = relight::lights::read_probe_image(file, {});
    if (frame.radiance.empty()) std::abort();
    for (const relight::Float3& p : frame.radiance.pixels()) {
      if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) std::abort();
      if (p.x < 0.f || p.y < 0.f || p.z < 0.f) std::abort();
    }
    if (!(frame.clipped_share >= 0.0 && frame.clipped_share <= 1.0)) std::abort();
  } catch (const relight::Error&) {
  }
  return 0;
}
