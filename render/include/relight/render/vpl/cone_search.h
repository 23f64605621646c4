#pragma once
// The point-cone search of BounceMethod::PointCone (vpl.h; Knecht's dissertation §5.2.7), on a
// batch of queries: where does the ray from `origin` along `direction` meet the surface, as far
// as a set of surface points tells?
//
// A point p (with normal n_p and splat half-size h) is a candidate of query (o, n, d) when
//   along = (p − o)·d > 0,
//   its distance from the ray is at most max(tan(α)·along, 2h): inside the cone of half-angle α
//     around d, widened near the apex to the points' spacing (a short hop, into a corner say,
//     would otherwise find no point inside the narrow tip),
//   (p − o)·n ≥ sin(α)·|p − o|: above the origin's tangent plane by the cone's angle (its own
//     surface must not catch a grazing direction).
// Its depth is where the ray meets its tangent plane, t = ((p − o)·n_p) / (d·n_p), or `along`
// where the ray grazes that plane (|d·n_p| < 0.2) or the plane lies behind (t ≤ 0). The
// candidate of least depth below `max_t` wins, the lower index on a tie; the hit is o + t·d.
// The dissertation compares the points' own distances instead, which in a cone that meets a wall
// obliquely picks the footprint's near end, up to distance·tan(α)/sin(elevation) from where the
// ray lands; with the tangent-plane depth a plane gives the ray's exact hit.
//
// cone_search_cpu is the reference; ConeSearchVk (cone_search_vk.h) runs it on the GPU, one work
// group per query reducing over the points.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "relight/render/vpl/surface_points.h"

namespace relight::render {

struct ConeQuery {
  Eigen::Vector3f origin;
  Eigen::Vector3f normal;     ///< unit, the origin surface's side the ray leaves from
  Eigen::Vector3f direction;  ///< unit
  float max_t = std::numeric_limits<float>::infinity();
};

struct ConeHit {
  static constexpr std::uint32_t kNone = 0xffffffffu;
  float t = std::numeric_limits<float>::infinity();
  std::uint32_t point = kNone;  ///< index into the points; kNone: no candidate
};

/// The cone's constants for a half-angle in degrees (0, 90).
struct ConeShape {
  explicit ConeShape(float half_angle_deg);
  float tan_half, sin_half;
};

/// The winner of one query (definition above).
[[nodiscard]] ConeHit cone_search(std::span<const IsmPoint> points, const ConeQuery& query, const ConeShape& cone);

/// cone_search for every query.
[[nodiscard]] std::vector<ConeHit> cone_search_cpu(std::span<const IsmPoint> points, std::span<const ConeQuery> queries,
                                                   float half_angle_deg);

}  // namespace relight::render
