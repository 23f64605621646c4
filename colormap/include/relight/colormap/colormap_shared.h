// Shared between C++ and the GLSL shaders of the statistics-based mapping, so that the
// push-constant layouts, work-group size and row layout of the partial sums cannot drift apart.
// Plain C preprocessor only (GLSL has no #pragma once).
#ifndef RELIGHT_COLORMAP_SHARED_H
#define RELIGHT_COLORMAP_SHARED_H

/// Pixels per work group of both passes (one invocation per pixel).
#define RELIGHT_COLORMAP_STATS_GROUP 256
/// Floats per row of the partial-sums buffer: count, source sum[3], source sum_sq[3],
/// target sum[3], target sum_sq[3], 3 padding.
#define RELIGHT_COLORMAP_SUMS_STRIDE 16

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// The tone-mapping operator (tone_map.h's ToneMap) as the shaders take it (std430: 12 bytes).
struct ColormapToneMap {
  float exposure;               ///< ToneMap::exposure
  float compression;            ///< k of tone_map.h: 1 Reinhard, 0 Exposure
  float inverse_white_squared;  ///< ToneMap::inverse_white_squared
};

/// Push constants of colormap_statistics.comp (std430: 16 bytes).
struct ColormapStatisticsParams {
  uint pixels;  ///< width * height
  ColormapToneMap tone_map;
};

/// Push constants of colormap_statistics_transfer.comp (std430: 40 bytes).
struct ColormapTransferParams {
  uint pixels;
  ColormapToneMap tone_map;
  float scale[3];   ///< ReinhardTransfer::scale (L, a, b)
  float offset[3];  ///< ReinhardTransfer::offset
};

#ifdef __cplusplus
static_assert(sizeof(ColormapToneMap) == 12);
static_assert(sizeof(ColormapStatisticsParams) == 16);
static_assert(sizeof(ColormapTransferParams) == 40);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_COLORMAP_SHARED_H
