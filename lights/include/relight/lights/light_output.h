#pragma once
// What `relight lights` writes: the LightSet as JSON and a picture of the probe with the lights.
#include <string>

#include "relight/core/image.h"
#include "relight/lights/light_set.h"
#include "relight/lights/probe_geometry.h"

namespace relight::lights {

/// {"lights": [{"type": "directional", "direction": [x,y,z], "power": [r,g,b], "real": true}, ...],
///  a point light with "position" instead of "direction", a spot with "position", "axis",
///  "cone_degrees" and "inner_degrees" (default 0.8 cone_degrees),
///  "count": N, "total_power": [r,g,b], "irradiance_up": [r,g,b]} (irradiance on a surface facing
/// world +z). Directions are in the scene frame; units as light_set.h.
[[nodiscard]] std::string lights_to_json(const LightSet& set);

/// "directional", "point" or "spot".
[[nodiscard]] const char* light_kind_name(LightKind kind);

/// Reads what lights_to_json writes (only "lights" is needed; "real" defaults to true). Throws
/// relight::Error naming `source` and the entry on malformed JSON, a missing field, an unknown
/// type, a non-finite number or negative power.
[[nodiscard]] LightSet lights_from_json(const std::string& text, const std::string& source);

/// The probe tone-mapped to 8-bit sRGB (exposure puts the 99th percentile of luminance at 0.8,
/// brighter values clip), each directional light marked by a ring whose radius grows with the
/// square root of its share of the power; the strongest 10 % in red, the others in green.
[[nodiscard]] ColorImage light_preview(const RadianceImage& probe, const ProbeGeometry& geometry, const LightSet& set);

}  // namespace relight::lights
