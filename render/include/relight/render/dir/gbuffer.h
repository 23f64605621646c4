#pragma once
// The G-buffer of one view (Knecht's dissertation §5.2.2): per pixel the nearest surface of the
// whole mixed-reality scene through the pixel centre, with the real/virtual flag r(p).
//
// gbuffer_cpu() casts one ray per pixel with Embree; it is the reference for the rasterised
// G-buffer (gbuffer_vk.h), which stores r(p) in the sign of the distance as the paper does.
#include "relight/core/image.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render {

struct GBuffer {
  PositionMap position;  ///< world frame, metres; (0,0,0) where nothing is seen
  NormalMap normal;      ///< world frame, unit, facing the camera (interpolated vertex normal)
  LabelImage material;   ///< MrScene material index + 1; 0 where nothing is seen
  Mask virtual_surface;  ///< 1 where the surface belongs to a virtual object (r(p) = 0)
  DepthMap distance;     ///< from the camera centre, metres; 0 where nothing is seen

  static constexpr const char* type_name = "GBuffer";
};

[[nodiscard]] GBuffer gbuffer_cpu(const RayTracer& tracer, const MrCamera& camera, int threads = 0);

}  // namespace relight::render
