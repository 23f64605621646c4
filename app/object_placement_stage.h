#pragma once
// Where each virtual object goes: `--place x,y,z[,yaw[,scale]]` in world coordinates, or on a
// real surface seen in the first frame: `--place-at u,v[,yaw[,scale]]` (the surface at that
// pixel, the object's up axis along its normal) or `--place-on-plane [yaw[,scale]]` (on a
// support plane - of the up-facing planes in view, the table, the floor, a shelf, the one seen
// free around the object's footprint nearest the image centre, and there: not under a
// monitor's foot, not against a wall).
//
// Stage ObjectPlacementStage ("object_placement")
//   reads:  "frame" (FrameInfo: intrinsics and the tracked camera_to_world), "depth" (DepthMap,
//           metres), "camera_pose" (CameraPose: whether the world frame is known yet)
//   writes: "object_placements" (render::ObjectPlacements), which DIR's mr_scene stage reads
//
// On a surface, yaw turns the object about the surface normal from facing the first camera (yaw
// 0: the model's front, +z, towards it), so it looks the same in any world frame the tracking
// chose. Surface placements are resolved once, on the first frame whose camera pose is valid (the
// first frame, except with a marker pose before the first tag sighting), and then held: an
// object stays where it was put, in the world frame, while the camera moves. The surface is a
// local plane fit (capture/support_plane.h), not one pixel's noisy normal. A pixel outside the
// image, without valid depth around it, or a first frame without a support plane is a
// relight::Error naming the option, the pixel and the frame.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "relight/capture/camera_pose.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/render/scene/virtual_model.h"

namespace relight::app {

/// One object's placement as the command line gave it.
struct PlacementRequest {
  enum class Kind { World, Pixel, SupportPlane };
  Kind kind = Kind::World;
  /// World: the whole placement. Pixel, SupportPlane: yaw and scale (position and up come from
  /// the surface).
  render::Placement placement;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< Pixel: (u, v) of the first frame
  std::string option;  ///< as typed, for messages: "--place-at 320,400"
  /// SupportPlane: the radius (metres, after scale) of the object's footprint, the disc of the
  /// plane that must be seen free; set by the caller from the model's bounds.
  double footprint_radius_m = 0.05;

  /// "x,y,z[,yaw[,scale]]"; throws relight::Error naming the text.
  static PlacementRequest world(const std::string& text);
  /// "u,v[,yaw[,scale]]".
  static PlacementRequest at_pixel(const std::string& text);
  /// "[yaw[,scale]]" (empty: yaw 0, scale 1).
  static PlacementRequest on_support_plane(const std::string& text);
};

/// The requests of `objects` objects: the --place ones first, then --place-at, then
/// --place-on-plane, in the order given; one per object. None at all on a synthetic sequence:
/// every object at `synthetic_default` (world). Throws relight::Error for a count mismatch or
/// a recorded sequence without any placement.
[[nodiscard]] std::vector<PlacementRequest> placement_requests(std::size_t objects,
                                                               const std::vector<std::string>& places,
                                                               const std::vector<std::string>& places_at,
                                                               const std::vector<std::string>& places_on_plane,
                                                               const char* synthetic_default, bool synthetic);

class ObjectPlacementStage final : public Stage {
 public:
  /// `names`: each object's name for the summary (its file name).
  ObjectPlacementStage(std::vector<PlacementRequest> requests, std::vector<std::string> names);
  [[nodiscard]] std::string name() const override { return "object_placement"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

  /// For report.json: per object, how it was placed and where it went (world position, up).
  [[nodiscard]] nlohmann::ordered_json summary() const;
  /// One line per surface placement once resolved ("glossy_pebble.gltf on the surface at pixel
  /// (320, 400): world (0.95, 1.40, 0.86) m, up (0.00, 0.01, 1.00)"), for the console.
  [[nodiscard]] std::string describe() const;

 private:
  [[nodiscard]] render::Placement resolve(const PlacementRequest& request, const FrameInfo& frame,
                                          const DepthMap& depth) const;
  std::vector<PlacementRequest> requests_;
  std::vector<std::string> names_;
  render::ObjectPlacements resolved_;
  std::int64_t resolved_frame_ = -1;
  Read<FrameInfo> frame_;
  Read<DepthMap> depth_;
  Read<capture::CameraPose> pose_;
  Write<render::ObjectPlacements> placements_;
};

}  // namespace relight::app
