#pragma once
// Shared fixtures of the colour-mapping tests: synthetic L_r / L_rv / L_cam triples (rendered
// once per process, 160x120) and the measure of the issue, the mean CIEDE2000 over the virtual
// object between the mapped composite and the object as the true camera would show it.
#include <map>
#include <string>

#include "relight/colormap/statistics_transfer.h"
#include "relight/truth/synthetic_camera.h"

namespace relight::colormap::test {

/// Orange sphere: a hue the real scene has (wood, red paint, yellow plastic).
inline const truth::SyntheticTriple& orange_triple() {
  static const truth::SyntheticTriple triple = truth::make_synthetic_triple({});
  return triple;
}

/// Green sphere: a hue absent from the real scene (where the channel-swap heuristic matters).
inline const truth::SyntheticTriple& green_triple() {
  static const truth::SyntheticTriple triple = [] {
    truth::SyntheticTripleOptions options;
    options.virtual_albedo = {0.15, 0.60, 0.20};
    return truth::make_synthetic_triple(options);
  }();
  return triple;
}

/// Mean CIEDE2000 over the virtual object of composite(L_cam, delta) against the truth.
inline double virtual_delta_e(const truth::SyntheticTriple& triple, const RadianceImage& delta) {
  return truth::mean_delta_e(composite(triple.camera, delta), triple.truth, virtual_mask(triple.real, triple.real_virtual));
}

}  // namespace relight::colormap::test
