// The point-cone search on the CPU (definition in cone_search.h).
#include "relight/render/vpl/cone_search.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace relight::render {

ConeShape::ConeShape(float half_angle_deg)
    : tan_half(std::tan(half_angle_deg * std::numbers::pi_v<float> / 180.f)),
      sin_half(std::sin(half_angle_deg * std::numbers::pi_v<float> / 180.f)) {}

ConeHit cone_search(std::span<const IsmPoint> points, const ConeQuery& query, const ConeShape& cone) {
  ConeHit best;
  best.t = query.max_t;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const IsmPoint& point = points[i];
    const Eigen::Vector3f offset = point.position - query.origin;
    const float along = offset.dot(query.direction);
    if (!(along > 0.f)) continue;
    const float distance = offset.norm();
    const float across_squared = std::max(0.f, distance * distance - along * along);
    const float radius = std::max(cone.tan_half * along, 2.f * point.half_size);
    if (across_squared > radius * radius || offset.dot(query.normal) < cone.sin_half * distance) continue;
    float t = along;
    const float facing = query.direction.dot(point.normal);
    if (std::fabs(facing) >= 0.2f) {
      const float plane_t = offset.dot(point.normal) / facing;
      if (plane_t > 0.f) t = plane_t;
    }
    if (!(t < best.t)) continue;
    best.t = t;
    best.point = static_cast<std::uint32_t>(i);
  }
  if (best.point == ConeHit::kNone) best.t = std::numeric_limits<float>::infinity();
  return best;
}

std::vector<ConeHit> cone_search_cpu(std::span<const IsmPoint> points, std::span<const ConeQuery> queries,
                                     float half_angle_deg) {
  const ConeShape cone(half_angle_deg);
  std::vector<ConeHit> hits(queries.size());
  for (std::size_t q = 0; q < queries.size(); ++q) hits[q] = cone_search(points, queries[q], cone);
  return hits;
}

}  // namespace relight::render
