#pragma once
// Point samples of the scene's surfaces, area-uniform, in two pools - real and virtual - as the
// imperfect shadow maps splat them (dir/ism.h: sample_ism_points) and the cone search finds
// bounce surfaces among them (cone_search.h).
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace relight::render {

struct IsmPoint {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;
  float half_size = 0.f;  ///< half the side of the point's square splat (metres)
  std::uint32_t material = 0;  ///< of the triangle the point lies on (MrScene::materials)
};

struct IsmPointPools {
  std::vector<IsmPoint> real;
  std::vector<IsmPoint> virtual_points;
  /// Centre and radius of a sphere around every virtual point; radius 0 = none, or focus off.
  Eigen::Vector4f virtual_bounds = Eigen::Vector4f::Zero();
  /// Centre and radius of a sphere around every point of both pools: what an emitter VPL's
  /// tiles look at (ism.h); radius 0 = no points.
  Eigen::Vector4f scene_bounds = Eigen::Vector4f::Zero();
};

}  // namespace relight::render
