#pragma once
// Real geometry from the screen-space reconstruction: the position map of one frame turned into
// a triangle grid in the world frame (Knecht's dissertation §5.2 does the same with the Kinect
// depth mesh).
//
// Reads a PositionMap (camera frame, (0,0,0) = invalid, as reconstruct/ writes it), optionally a
// NormalMap (camera frame) and a LabelImage of material clusters; writes one real TriangleMesh.
// Each grid cell of 2x2 pixels gives two triangles; a triangle is dropped when a vertex is
// invalid or one of its edges is longer than max(min_edge, relative_edge * depth): across a
// depth discontinuity (an object's outline against the background) neighbouring pixels are far
// apart, and bridging them would put a wall of fake geometry into shadows and ISMs.
#include <optional>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/render/scene/mr_scene.h"

namespace relight::render {

struct DepthMeshOptions {
  float relative_edge = 0.03f;  ///< longest edge as a fraction of the depth (~80 deg slant at stride 1)
  float min_edge = 0.01f;       ///< metres: never drop edges shorter than this
  int stride = 1;               ///< pixels between grid vertices (2 = quarter the triangles)
};

/// Material of every triangle: `material`, or material_of_label[label] when labels are given
/// (a label outside the table falls back to `material`).
struct DepthMeshMaterials {
  std::uint32_t material = 0;
  const LabelImage* labels = nullptr;
  std::vector<std::uint32_t> material_of_label;
};

[[nodiscard]] TriangleMesh mesh_from_positions(const PositionMap& positions, const NormalMap* normals,
                                               const Pose& camera_to_world, const DepthMeshMaterials& materials,
                                               const DepthMeshOptions& options = {});

/// Camera-frame positions of a depth map (invalid depth -> (0,0,0)).
[[nodiscard]] PositionMap positions_from_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics);

}  // namespace relight::render
