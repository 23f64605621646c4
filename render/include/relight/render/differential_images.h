#pragma once
// What every differential renderer writes (Knecht 2010 §3, eq. 1: the composite adds
// TM(L_rv) - TM(L_r) to the camera image where the virtual coverage is zero): the path tracer
// (reference/path_tracer.h), DIR on the CPU and the GPU (dir/dir_vk.h), and the renderers to come.
#include "relight/core/image.h"

namespace relight::render {

/// Fraction of a pixel's camera samples that first hit a virtual object, in [0, 1].
struct CoverageImage : Image<float> {
  using Image<float>::Image;
  static constexpr const char* type_name = "CoverageImage";
};

struct DifferentialImages {
  RadianceImage real_virtual;  ///< L_rv
  RadianceImage real;          ///< L_r
  CoverageImage virtual_coverage;
  int samples_per_pixel = 0;
  /// The indirect (VPL) part of L_rv and L_r, included in them; filled by the DIR renderers
  /// (dir/dir_vk.h) for temporal smoothing, empty otherwise.
  RadianceImage indirect_real_virtual;
  RadianceImage indirect_real;

  static constexpr const char* type_name = "DifferentialImages";
};

}  // namespace relight::render
