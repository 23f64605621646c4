#pragma once
// Where the AprilTag markers are in the world: per tag its id, edge length and the four corners
// of its black square in world coordinates, in AprilTag's corner order (tag frame (-s/2, +s/2),
// (+s/2, +s/2), (+s/2, -s/2), (-s/2, -s/2) with x right and y down in the tag image; the order
// apriltag_detection_t::p reports them in the image).
//
// JSON, either a layout file
//   {"family": "tag36h11", "tags": [{"id": 0, "size": 0.16, "corners_world": [[x,y,z] x 4]}]}
// or a scene.json written by `relight synth` (its "tag" object has the same fields).
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace relight::capture {

struct TagLayout {
  struct Tag {
    int id = 0;
    double size = 0.0;  ///< metres, edge of the black square
    std::array<Eigen::Vector3d, 4> corners_world{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                 Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    /// The centre of the black square, world frame.
    [[nodiscard]] Eigen::Vector3d centre() const {
      return 0.25 * (corners_world[0] + corners_world[1] + corners_world[2] + corners_world[3]);
    }
    /// The unit normal of its face, (corner 1 - corner 0) x (corner 3 - corner 0), world frame.
    [[nodiscard]] Eigen::Vector3d normal() const {
      return (corners_world[1] - corners_world[0]).cross(corners_world[3] - corners_world[0]).normalized();
    }
  };
  std::string family = "tag36h11";
  std::vector<Tag> tags;

  [[nodiscard]] const Tag* find(int id) const;
};

/// Parses layout JSON text; `origin` names the source in error messages. Throws relight::Error.
[[nodiscard]] TagLayout parse_tag_layout(std::string_view json_text, const std::string& origin);
/// Reads a layout file or a scene.json. Throws relight::Error naming the file.
[[nodiscard]] TagLayout read_tag_layout(const std::filesystem::path& file);

}  // namespace relight::capture
