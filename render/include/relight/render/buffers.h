#pragma once
// The names of the renderers' own frame-graph buffers (buffer_name.h); core/buffers.h has L_rv,
// L_r and the composites.
#include "relight/core/buffer_name.h"
#include "relight/render/differential_images.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/dir/specular_back_projection.h"
#include "relight/render/dir/temporal_smoothing.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/scene/virtual_model.h"
#include "relight/render/vpl/vpl.h"

namespace relight::render {

inline constexpr BufferName<ObjectPlacements> kObjectPlacements{"object_placements"};
inline constexpr BufferName<MrScene> kMrScene{"mr_scene"};
inline constexpr BufferName<VplSet> kVpls{"vpls"};
inline constexpr BufferName<DifferentialImages> kDirImages{"dir_images"};
inline constexpr BufferName<GBuffer> kDirGBuffer{"dir_gbuffer"};
/// What the frame's mirrors and glass show, back-projected into the camera image (empty without).
inline constexpr BufferName<SpecularBackProjection> kSpecularBackProjection{"specular_back_projection"};
inline constexpr BufferName<CoverageImage> kVirtualCoverage{"virtual_coverage"};
/// The indirect light's temporal smoothing state (G-buffer, camera, indirect light of the last
/// frame), a history the graph keeps.
inline constexpr BufferName<TemporalHistory> kIndirectHistory{"indirect_history"};

}  // namespace relight::render
