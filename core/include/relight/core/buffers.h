#pragma once
// The names of the pipeline's frame-graph buffers whose types are core's (images, frame info),
// each defined once with its type (buffer_name.h). A library's own buffer types have their names
// beside them, in <library>/buffers.h. Stages default to these names; app/replay.cpp wires the
// main pipeline with them.
#include "relight/core/buffer_name.h"
#include "relight/core/image.h"
#include "relight/core/rgbd_frame.h"

namespace relight {

// capture/: the source and the tracked camera
inline constexpr BufferName<ColorImage> kColor{"color"};              ///< the camera's colour image
inline constexpr BufferName<DepthMap> kDepth{"depth"};                ///< raw depth, metres
inline constexpr BufferName<FrameInfo> kSourceFrame{"source_frame"};  ///< as the source gave it
inline constexpr BufferName<FrameInfo> kFrame{"frame"};               ///< with the tracked camera pose

// reconstruct/: filtered depth and the geometry of the frame (camera frame)
inline constexpr BufferName<DepthMap> kDepthSmoothed{"depth_smoothed"};  ///< method 1's box filter
inline constexpr BufferName<DepthMap> kDepthFiltered{"depth_filtered"};  ///< method 2's warp + merge
inline constexpr BufferName<PositionMap> kPositions{"positions"};
inline constexpr BufferName<NormalMap> kNormals{"normals"};

// lights/: the light probe image
inline constexpr BufferName<RadianceImage> kProbe{"probe"};

// brdf/: highlight removal and the diffuse reflectance
inline constexpr BufferName<ColorImage> kColorDiffuse{"color_diffuse"};
inline constexpr BufferName<Mask> kHighlightMask{"highlight_mask"};
inline constexpr BufferName<RadianceImage> kKd{"kd"};
inline constexpr BufferName<Mask> kKdValid{"kd_valid"};
inline constexpr BufferName<ColorImage> kBrdfPreview{"brdf_preview"};

// render/: the two radiances of differential rendering and the composites
inline constexpr BufferName<RadianceImage> kRealVirtualRadiance{"L_rv"};
inline constexpr BufferName<RadianceImage> kRealRadiance{"L_r"};
inline constexpr BufferName<RadianceImage> kRealVirtualIndirect{"L_rv_indirect"};  ///< the VPL part of L_rv
inline constexpr BufferName<ColorImage> kComposite{"composite"};
inline constexpr BufferName<ColorImage> kCompositeMapped{"composite_mapped"};

// colormap/: the colour-mapped difference and the mapped image
inline constexpr BufferName<RadianceImage> kDeltaRadiance{"delta_L"};
inline constexpr BufferName<ColorImage> kColorMapped{"color_mapped"};

}  // namespace relight
