// Shared between C++ (cone_search_vk.cpp) and GLSL (shaders/cone_search.comp), so the
// push-constant layout, the packed records and the work-group size cannot drift apart. Plain C
// preprocessor only (GLSL has no #pragma once); in GLSL `uint` is the built-in type.
#ifndef RELIGHT_RENDER_CONE_SEARCH_SHARED_H
#define RELIGHT_RENDER_CONE_SEARCH_SHARED_H

/// Invocations per work group of cone_search.comp: one group per query, each invocation scans
/// every RELIGHT_CONE_LOCAL_SIZE-th point, then the group reduces.
#define RELIGHT_CONE_LOCAL_SIZE 64
/// Floats per packed point: position, half-size, normal, padding.
#define RELIGHT_CONE_POINT_FLOATS 8
/// Floats per packed query: origin, max_t, normal, padding, direction, padding.
#define RELIGHT_CONE_QUERY_FLOATS 12
/// A query's result when no point qualifies.
#define RELIGHT_CONE_NO_POINT 0xffffffffu

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of cone_search.comp. Results are two words per query: t's float bits, index.
struct ConeSearchParams {
  uint point_count;
  uint query_count;
  float tan_half;
  float sin_half;
};

#ifdef __cplusplus
static_assert(sizeof(ConeSearchParams) == 16);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RENDER_CONE_SEARCH_SHARED_H
