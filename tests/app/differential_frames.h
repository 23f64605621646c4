#pragma once
// Reading what `relight replay --buffers` and `relight render-reference` write, and the measures
// the dynamic-light tests take of them: the light a virtual object takes from the real table (its
// shadow), DIR's differential light against the path tracer's, and the direction in which the
// object's shadow falls on the table (issue: dynamic real light, "Measure it").
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "relight/core/image.h"

namespace relight::app::frames_test {

/// frames/<frame, 6 digits><suffix>, as the frame writer names its files.
std::filesystem::path frame_file(const std::filesystem::path& frames, int frame, const char* suffix);

/// The light the virtual object takes from real surfaces: sums over pixels it does not cover.
struct FrameLight {
  double shadow = 0.0;      ///< sum of L_r - L_rv (its shadow; its bounce light counts against it)
  double real_light = 0.0;  ///< mean of L_r
  double camera = 0.0;      ///< mean linear camera value over the same pixels
};
FrameLight frame_light(const std::filesystem::path& frames, int frame);

/// Differential light L_rv - L_r summed over the channels, and where the virtual object covers
/// the pixel (those carry the object itself, not its effect on the real scene).
struct DeltaLight {
  Image<float> delta;
  Image<std::uint8_t> covered;
};
/// Of a replayed frame (frames/<frame>_L_rv.exr, _L_r.exr, _virtual_coverage.png).
DeltaLight replayed_delta(const std::filesystem::path& frames, int frame);
/// Of a render-reference output (`reference` = L_rv, beside it .Lr.exr) rendered at the replay's
/// resolution; the covered pixels are the replay's `coverage` grown by one pixel (the reference
/// writes no coverage, and its object edge is anti-aliased over the neighbours).
DeltaLight reference_delta(const std::filesystem::path& reference, const Image<std::uint8_t>& coverage);

/// Over the pixels covered in neither, where `region` (if not empty) is true: the relative error
/// sum |ours - truth| / sum |truth|, and sum ours / sum truth (how much of the truth's light
/// change ours has: a scale error shows here, a misplaced shadow does not).
struct DeltaError {
  double relative = 1.0;
  double ours_over_truth = 0.0;
};
DeltaError delta_relative_error(const DeltaLight& ours, const DeltaLight& truth,
                                const Image<std::uint8_t>& region = {});

/// Relative error of DIR's differential light L_rv - L_r of `frame` against the path tracer's
/// (render-reference at half the resolution: `reference` holds L_rv, beside it .Lr.exr), summed
/// over the pixels the virtual object covers in none of the 2x2 replay pixels they average.
double delta_error_against_reference(const std::filesystem::path& frames, int frame,
                                     const std::filesystem::path& reference);

/// The camera of a synthetic sequence's frame (scene.json's intrinsics, groundtruth.txt's pose)
/// and its table top (scene.json's `table_top` box): what maps a pixel to the table point it sees.
struct TableView {
  Eigen::Matrix3d camera_to_world_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d camera_position = Eigen::Vector3d::Zero();
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Eigen::Vector3d table_min = Eigen::Vector3d::Zero(), table_max = Eigen::Vector3d::Zero();
  /// The table-top point pixel (col, row) sees, if its ray meets the top's plane within the top.
  [[nodiscard]] bool table_point(int col, int row, Eigen::Vector2d& point) const;
};
TableView table_view(const std::filesystem::path& sequence, int frame);

/// A virtual object's shadow on the table: the uncovered pixels that see the table top within
/// `radius` (metres) of the object's foot where the differential light is at least `depth` times
/// its deepest value there.
Image<std::uint8_t> shadow_region(const DeltaLight& light, const TableView& view, const Eigen::Vector2d& foot,
                                  double depth = 0.3, double radius = 0.5);

/// The direction in which a virtual object's shadow (shadow_region) falls on the table, seen
/// from above, each point weighted by how much light the object takes there.
struct ShadowDirection {
  /// Azimuth (degrees, counter-clockwise from world x) of the weighted centroid seen from the
  /// object's foot: where the shadow lies.
  double azimuth_degrees = 0;
  /// Azimuth of the region's principal axis (its weighted second moments about the centroid),
  /// signed to point away from the foot: along what the shadow stretches.
  double axis_degrees = 0;
  double centroid_distance = 0;  ///< metres from the foot
  int pixels = 0;
};
ShadowDirection shadow_direction(const DeltaLight& light, const TableView& view, const Eigen::Vector2d& foot,
                                 double depth = 0.3, double radius = 0.5);

/// The smallest angle between two azimuths in degrees, in [0, 180].
double azimuth_difference(double a_degrees, double b_degrees);

}  // namespace relight::app::frames_test
