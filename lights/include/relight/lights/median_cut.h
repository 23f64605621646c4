#pragma once
// Median cut light extraction: Debevec, "A Median Cut Algorithm for Light Probe Sampling",
// SIGGRAPH 2005 poster / Franke's Delta Radiance Fields.
//
// The probe image (in its own pixel grid, fisheye or lat-long) is split into rectangular regions
// of equal energy (energy = sum of luminance x solid angle): a region is cut across its longer
// side (lat-long widths scaled by sin(theta), as Debevec does) where the energy on either side is
// equal. Debevec splits every region k times for 2^k lights; here the region with the most energy
// is split next until there are N, which is the same for N = 2^k and also allows other N.
// Each region becomes one directional light at its energy centroid, with power = the sum of
// radiance x solid angle over the region, so the lights' powers add up exactly to the probe's
// integral of radiance over the sphere, and sum_i power_i max(0, n.d_i) approximates the
// irradiance on a surface of normal n.
#include "relight/core/image.h"
#include "relight/lights/light_set.h"
#include "relight/lights/probe_geometry.h"

namespace relight::lights {

struct MedianCutOptions {
  int lights = 64;  ///< N
};

/// Throws relight::Error when the probe is black or does not match the geometry's size. Fewer
/// than N lights come back only when single pixels cannot be split further.
[[nodiscard]] LightSet median_cut(const RadianceImage& probe, const ProbeGeometry& geometry,
                                  const MedianCutOptions& options);

}  // namespace relight::lights
