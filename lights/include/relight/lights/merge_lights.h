#pragma once
// Fewer directional lights for the stages whose cost grows with every light (BRDF estimation,
// brdf/): the directional lights of a set, merged pairwise, nearest directions first, until at
// most `max_directional` of each kind (real, virtual) are left. A merged light carries the sum of
// its parts' power (the energy stays) along their luminance-weighted mean direction; for a
// normal that faces all parts, its irradiance differs from theirs by at most 1 / cos(theta / 2)
// with theta the angle between the parts: a probe's 64 importance samples merged to 8 clusters
// are what extracting 8 lights from the probe would have given.
//
// Reads and writes lights::LightSet; point and spot lights pass unchanged, first, in order, then
// the real and the virtual directional lights; a set within the limit comes back as it is.
#include <cstddef>

#include "relight/lights/light_set.h"

namespace relight::lights {

[[nodiscard]] LightSet merge_directional_lights(const LightSet& set, std::size_t max_directional);

/// The same merge, closest pair first, until no two directional lights of a kind are within
/// `max_angle_degrees` of each other (0 or less: the set as it is). For the renderer's direct
/// pass, where every directional light costs two shadow maps and two lookups a pixel: a probe's
/// importance samples crowd onto its brightest source (five of the synthetic room's eight lie
/// within 2 degrees of its key light), and such near-copies cast one shadow.
[[nodiscard]] LightSet merge_close_directional_lights(const LightSet& set, double max_angle_degrees);

}  // namespace relight::lights
