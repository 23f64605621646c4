#pragma once
// The two virtual objects shipped in data/models/, built here so that they can be regenerated
// (`relight models --out DIR`) and checked against the committed files. Both are y-up with the
// origin at the middle of the base (see virtual_model.h), sized for a table top.
#include "relight/render/scene/virtual_model.h"

namespace relight::render {

/// A smooth, lobed "pebble" about 0.16 m wide and 0.12 m high (a sphere displaced by low-order
/// harmonics), glossy red Phong (k_d 0.55/0.08/0.06, k_s 0.35, n 60) - the glossy test object
/// for highlights and colour bleeding. `segments` sets the resolution (48 around, 24 rings by default: ~2200 triangles).
[[nodiscard]] VirtualModel make_glossy_pebble(int segments = 48);

/// The pebble's shape in pale green glass (index 1.5, attenuation colour 0.80/0.95/0.85 per 0.1 m;
/// specular_material.h): the refractive test object (caustics, what is seen through it).
[[nodiscard]] VirtualModel make_glass_pebble(int segments = 48);

/// A 0.2 m bottle of polished aluminium (a mirror of reflectance 0.91/0.92/0.92), 7 cm across:
/// the reflective test object.
[[nodiscard]] VirtualModel make_metal_bottle(int segments = 48);

/// A 0.12 m cube, matte light blue (k_d 0.20/0.35/0.60) - a simple occluder.
[[nodiscard]] VirtualModel make_matte_box();

}  // namespace relight::render
