#include "object_placement_stage.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

#include "number_list.h"
#include "relight/capture/buffers.h"
#include "relight/capture/support_plane.h"
#include "relight/core/buffers.h"
#include "relight/core/error.h"
#include "relight/core/pixel.h"
#include "relight/render/buffers.h"

namespace relight::app {

namespace {

/// The numbers of `text` (empty: none), between `min` and `max` of them; throws naming `option`.
std::vector<double> numbers(const std::string& option, const std::string& text, std::size_t min, std::size_t max,
                            const char* form) {
  std::vector<double> values = parse_number_list<double>(option, text, form);
  if (values.size() < min || values.size() > max) throw Error(option + " '" + text + "' needs " + form);
  return values;
}

/// Yaw and scale from values[first], values[first + 1] when present.
void yaw_and_scale(render::Placement& placement, const std::vector<double>& values, std::size_t first,
                   const std::string& option) {
  if (values.size() > first) placement.yaw_degrees = values[first];
  if (values.size() > first + 1) placement.scale = values[first + 1];
  if (!(placement.scale > 0.0)) throw Error(option + ": the scale must be positive");
}

std::string vector_text(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.2f, %.2f, %.2f)", v.x(), v.y(), v.z());
  return text;
}

nlohmann::ordered_json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

const char* kind_name(PlacementRequest::Kind kind) {
  switch (kind) {
    case PlacementRequest::Kind::World: return "world";
    case PlacementRequest::Kind::Pixel: return "pixel";
    case PlacementRequest::Kind::SupportPlane: return "support_plane";
  }
  return "?";
}

/// The pixel nearest the image centre whose surroundings, a square as wide as the footprint's
/// disc at that depth, show the plane for at least 90 % of their pixels: the centre itself may
/// show something standing on the plane, or the plane only as a sliver beside it.
struct FreeSpot {
  capture::Plane plane;
  Eigen::Vector2i pixel;
  double distance2;  ///< squared pixels from the image centre
};

std::optional<FreeSpot> free_spot_nearest_centre(const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                                 const capture::Plane& plane, double footprint_radius_m) {
  const int width = depth.width(), height = depth.height();
  const capture::SupportPlaneOptions tolerance;
  // Integral image of the plane's inlier pixels: the share of any box in O(1).
  std::vector<int> sum(static_cast<std::size_t>(width + 1) * static_cast<std::size_t>(height + 1), 0);
  const auto at = [width](int row, int col) { return static_cast<std::size_t>(row) * static_cast<std::size_t>(width + 1) + static_cast<std::size_t>(col); };
  struct Candidate {
    double distance2;
    int row, col;
  };
  std::vector<Candidate> candidates;
  const double cu = 0.5 * (width - 1), cv = 0.5 * (height - 1);
  for (int row = 0; row < height; ++row) {
    int row_sum = 0;
    for (int col = 0; col < width; ++col) {
      const float z = depth(row, col);
      const bool on_plane = is_valid_depth(z) && plane.holds(intrinsics.unproject(col, row, z), tolerance.tolerance_m);
      row_sum += on_plane;
      sum[at(row + 1, col + 1)] = sum[at(row, col + 1)] + row_sum;
      if (on_plane) candidates.push_back({(col - cu) * (col - cu) + (row - cv) * (row - cv), row, col});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.distance2 < b.distance2; });
  for (const Candidate& c : candidates) {
    const int half = static_cast<int>(std::ceil(intrinsics.fx * footprint_radius_m / depth(c.row, c.col)));
    const int top = c.row - half, bottom = c.row + half + 1, left = c.col - half, right = c.col + half + 1;
    if (top < 0 || left < 0 || bottom > height || right > width) continue;
    const int inliers = sum[at(bottom, right)] - sum[at(top, right)] - sum[at(bottom, left)] + sum[at(top, left)];
    if (inliers >= 0.9 * (bottom - top) * (right - left)) return FreeSpot{plane, {c.col, c.row}, c.distance2};
  }
  return std::nullopt;
}

}  // namespace

PlacementRequest PlacementRequest::world(const std::string& text) {
  PlacementRequest request;
  request.placement = render::Placement::parse(text);
  request.option = "--place " + text;
  return request;
}

PlacementRequest PlacementRequest::at_pixel(const std::string& text) {
  PlacementRequest request;
  request.kind = Kind::Pixel;
  request.option = "--place-at " + text;
  const auto values = numbers("--place-at", text, 2, 4, "u,v[,yaw_degrees[,scale]]");
  request.pixel = {values[0], values[1]};
  yaw_and_scale(request.placement, values, 2, request.option);
  return request;
}

PlacementRequest PlacementRequest::on_support_plane(const std::string& text) {
  PlacementRequest request;
  request.kind = Kind::SupportPlane;
  request.option = text.empty() ? "--place-on-plane" : "--place-on-plane " + text;
  const auto values = numbers("--place-on-plane", text, 0, 2, "[yaw_degrees[,scale]]");
  yaw_and_scale(request.placement, values, 0, request.option);
  return request;
}

std::vector<PlacementRequest> placement_requests(std::size_t objects, const std::vector<std::string>& places,
                                                 const std::vector<std::string>& places_at,
                                                 const std::vector<std::string>& places_on_plane,
                                                 const char* synthetic_default, bool synthetic) {
  std::vector<PlacementRequest> requests;
  for (const auto& text : places) requests.push_back(PlacementRequest::world(text));
  for (const auto& text : places_at) requests.push_back(PlacementRequest::at_pixel(text));
  for (const auto& text : places_on_plane) requests.push_back(PlacementRequest::on_support_plane(text));
  if (requests.empty() && objects > 0) {
    if (!synthetic) {
      throw Error("an object in a recorded scene needs a placement: --place x,y,z[,yaw[,scale]], "
                  "--place-at u,v[,yaw[,scale]] or --place-on-plane [yaw[,scale]]");
    }
    for (std::size_t i = 0; i < objects; ++i) requests.push_back(PlacementRequest::world(synthetic_default));
  }
  if (requests.size() != objects) {
    throw Error("give one placement (--place, --place-at or --place-on-plane) per --object (" +
                std::to_string(objects) + " objects, " + std::to_string(requests.size()) + " placements)");
  }
  return requests;
}

ObjectPlacementStage::ObjectPlacementStage(std::vector<PlacementRequest> requests, std::vector<std::string> names)
    : requests_(std::move(requests)), names_(std::move(names)) {
  if (names_.size() != requests_.size()) throw LogicError("object_placement: one name per placement");
}

void ObjectPlacementStage::declare(StageBuilder& builder) {
  frame_ = builder.read(kFrame);
  depth_ = builder.read(kDepth);
  pose_ = builder.read(capture::kCameraPose);
  placements_ = builder.write(render::kObjectPlacements);
}

void ObjectPlacementStage::run(StageContext& context) {
  if (!resolved_.resolved && context.get(pose_).valid) {
    const FrameInfo& frame = context.get(frame_);
    const DepthMap& depth = context.get(depth_);
    for (const PlacementRequest& request : requests_) resolved_.placements.push_back(resolve(request, frame, depth));
    resolved_.resolved = true;
    resolved_frame_ = frame.index;
  }
  context.get(placements_) = resolved_;
}

render::Placement ObjectPlacementStage::resolve(const PlacementRequest& request, const FrameInfo& frame,
                                                const DepthMap& depth) const {
  if (request.kind == PlacementRequest::Kind::World) return request.placement;
  const PinholeIntrinsics& intrinsics = frame.intrinsics;
  const std::string where = " of frame " + std::to_string(frame.index);
  std::optional<Eigen::Vector3d> point;
  Eigen::Vector3d normal;
  if (request.kind == PlacementRequest::Kind::Pixel) {
    const Eigen::Vector2d& pixel = request.pixel;
    char at[64];
    std::snprintf(at, sizeof at, "pixel (%g, %g)", pixel.x(), pixel.y());
    if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > depth.width() - 1 || pixel.y() > depth.height() - 1) {
      throw Error(request.option + ": " + at + " is outside the " + std::to_string(depth.width()) + "x" +
                  std::to_string(depth.height()) + " image");
    }
    const auto plane = capture::local_plane_at(depth, intrinsics, pixel.x(), pixel.y());
    if (!plane) throw Error(request.option + ": no surface at " + at + where + " (too little valid depth around it)");
    point = plane->ray_hit(intrinsics, pixel.x(), pixel.y());
    if (!point) throw Error(request.option + ": the surface at " + at + where + " is seen edge-on");
    normal = plane->normal;
  } else {
    // The up-facing planes in view (the table, the floor, a shelf): the object goes onto the one
    // whose free spot is nearest the image centre, the surface the camera looks at.
    capture::SupportPlaneOptions support;
    support.min_inlier_share = 0.03;
    const auto planes = capture::support_planes(depth, intrinsics, 3, support);
    if (planes.empty()) throw Error(request.option + ": no support plane in frame " + std::to_string(frame.index) +
                                    " (no up-facing plane holds enough of the depth; try --place-at u,v)");
    std::optional<FreeSpot> best;
    for (const capture::Plane& plane : planes) {
      const auto spot = free_spot_nearest_centre(depth, intrinsics, plane, request.footprint_radius_m);
      if (spot && (!best || spot->distance2 < best->distance2)) best = spot;
    }
    if (!best) {
      throw Error(request.option + ": the support plane of frame " + std::to_string(frame.index) +
                  " has no free spot for the object in view (try --place-at u,v)");
    }
    point = best->plane.ray_hit(intrinsics, best->pixel.x(), best->pixel.y());
    if (!point) throw Error(request.option + ": the support plane of frame " + std::to_string(frame.index) + " is seen edge-on");
    normal = best->plane.normal;
  }
  const Pose camera_to_world = frame.camera_to_world.value_or(Pose::Identity());
  render::Placement placement = request.placement;
  placement.position = camera_to_world * *point;
  placement.up = (camera_to_world.linear() * normal).normalized();
  // Yaw 0 turns the model's front (+z) towards the first camera, so that the object looks the
  // same whichever world frame the tracking chose (a levelled odometry world, mocap, a marker's).
  const Eigen::Vector3d to_camera = camera_to_world.translation() - placement.position;
  const Eigen::Vector3d along_surface = to_camera - to_camera.dot(placement.up) * placement.up;
  if (along_surface.norm() > 1e-6) {
    // transform(): front -> (sin yaw, -cos yaw, 0) in the z-up frame, then z is turned onto up.
    const Eigen::Vector3d e =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), placement.up).inverse() * along_surface.normalized();
    placement.yaw_degrees += std::atan2(e.x(), -e.y()) * 180.0 / std::numbers::pi;
  }
  return placement;
}

nlohmann::ordered_json ObjectPlacementStage::summary() const {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < requests_.size(); ++i) {
    nlohmann::ordered_json entry;
    entry["object"] = names_[i];
    entry["placement"] = kind_name(requests_[i].kind);
    entry["option"] = requests_[i].option;
    if (resolved_.resolved) {
      const render::Placement& placement = resolved_.placements[i];
      entry["frame"] = resolved_frame_;
      entry["position_m"] = vector_json(placement.position);
      entry["up"] = vector_json(placement.up);
      entry["yaw_degrees"] = placement.yaw_degrees;  // about up, in the world frame
      if (requests_[i].kind != PlacementRequest::Kind::World)
        entry["yaw_from_camera_degrees"] = requests_[i].placement.yaw_degrees;  // as given
      entry["scale"] = placement.scale;
    } else {
      entry["frame"] = nullptr;  // no frame had a camera pose: the object was never drawn
    }
    out.push_back(std::move(entry));
  }
  return out;
}

std::string ObjectPlacementStage::describe() const {
  std::string out;
  if (!resolved_.resolved) return out;
  for (std::size_t i = 0; i < requests_.size(); ++i) {
    const PlacementRequest& request = requests_[i];
    if (request.kind == PlacementRequest::Kind::World) continue;
    const render::Placement& placement = resolved_.placements[i];
    out += names_[i] + " (" + request.option + ", frame " + std::to_string(resolved_frame_) + "): world " +
           vector_text(placement.position) + " m, up " + vector_text(placement.up) + "\n";
  }
  return out;
}

}  // namespace relight::app
