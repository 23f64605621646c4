// Fuzzes `--lights FILE` (lights/light_output.h, lights_from_json): the input is the lights JSON
// `relight lights` writes. relight::Error is the answer to a malformed file; any other exception,
// a crash or a sanitizer report is a finding. A parsed light set must be one the renderer can
// use: finite, non-negative power, unit directions and axes, spot cones within (0, 90] degrees
// with the inner cone inside the outer one.
#include <cmath>
#include <cstdlib>

#include "fuzz_input.h"
#include "relight/core/error.h"
#include "relight/lights/light_output.h"

namespace {

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }
bool unit(const Eigen::Vector3d& v) { return finite(v) && std::abs(v.norm() - 1.0) < 1e-6; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const relight::lights::LightSet set =
        relight::lights::lights_from_json(std::string(relight::fuzz::as_text(data, size)), "lights.json");
    for (const relight::lights::Light& light : set.lights) {
      if (!finite(light.power) || (light.power.array() < 0.0).any()) std::abort();
      if (!finite(light.position)) std::abort();
      switch (light.kind) {
        case relight::lights::LightKind::Directional:
          if (!unit(light.direction)) std::abort();
          break;
        case relight::lights::LightKind::Point: break;
        case relight::lights::LightKind::Spot:
          if (!unit(light.axis)) std::abort();
          if (!(light.cone_degrees > 0.0 && light.cone_degrees <= 90.0)) std::abort();
          if (!(light.inner_degrees > 0.0 && light.inner_degrees <= light.cone_degrees)) std::abort();
          break;
      }
    }
  } catch (const relight::Error&) {
  }
  return 0;
}
