#include "differential_frames.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"

namespace relight::app::frames_test {
namespace {

double srgb_to_linear(std::uint8_t v) {
  const double c = v / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double channel_sum(const Float3& v) { return static_cast<double>(v.x) + v.y + v.z; }

Image<float> difference(const RadianceImage& real_virtual, const RadianceImage& real) {
  Image<float> delta(real.width(), real.height());
  for (std::size_t i = 0; i < delta.size(); ++i)
    delta.data()[i] = static_cast<float>(channel_sum(real_virtual.data()[i]) - channel_sum(real.data()[i]));
  return delta;
}

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

}  // namespace

std::filesystem::path frame_file(const std::filesystem::path& frames, int frame, const char* suffix) {
  char stem[16];
  std::snprintf(stem, sizeof stem, "%06d", frame);
  return frames / (std::string(stem) + suffix);
}

FrameLight frame_light(const std::filesystem::path& frames, int frame) {
  const RadianceImage lrv = read_radiance(frame_file(frames, frame, "_L_rv.exr"));
  const RadianceImage lr = read_radiance(frame_file(frames, frame, "_L_r.exr"));
  const ColorImage coverage = read_color(frame_file(frames, frame, "_virtual_coverage.png"));
  const ColorImage camera = read_color(frame_file(frames, frame, "_color.png"));
  FrameLight light;
  double count = 0.0;
  for (int row = 0; row < lrv.height(); ++row) {
    for (int col = 0; col < lrv.width(); ++col) {
      if (coverage(row, col).r != 0) continue;
      light.shadow += channel_sum(lr(row, col)) - channel_sum(lrv(row, col));
      light.real_light += channel_sum(lr(row, col));
      const Rgb8 c = camera(row, col);
      light.camera += srgb_to_linear(c.r) + srgb_to_linear(c.g) + srgb_to_linear(c.b);
      count += 1.0;
    }
  }
  light.real_light /= count;
  light.camera /= count;
  return light;
}

DeltaLight replayed_delta(const std::filesystem::path& frames, int frame) {
  const ColorImage coverage = read_color(frame_file(frames, frame, "_virtual_coverage.png"));
  DeltaLight light{difference(read_radiance(frame_file(frames, frame, "_L_rv.exr")),
                              read_radiance(frame_file(frames, frame, "_L_r.exr"))),
                   Image<std::uint8_t>(coverage.width(), coverage.height())};
  for (std::size_t i = 0; i < coverage.size(); ++i) light.covered.data()[i] = coverage.data()[i].r != 0 ? 1 : 0;
  return light;
}

DeltaLight reference_delta(const std::filesystem::path& reference, const Image<std::uint8_t>& coverage) {
  auto real_path = reference;
  DeltaLight light{difference(read_radiance(reference), read_radiance(real_path.replace_extension(".Lr.exr"))),
                   Image<std::uint8_t>(coverage.width(), coverage.height())};
  if (!light.delta.same_shape(coverage)) {
    ADD_FAILURE() << reference << " is not at the replay's resolution";
    return {};
  }
  for (int row = 0; row < coverage.height(); ++row) {
    for (int col = 0; col < coverage.width(); ++col) {
      if (coverage(row, col) == 0) continue;
      for (int r = std::max(0, row - 1); r <= std::min(coverage.height() - 1, row + 1); ++r)
        for (int c = std::max(0, col - 1); c <= std::min(coverage.width() - 1, col + 1); ++c) light.covered(r, c) = 1;
    }
  }
  return light;
}

DeltaError delta_relative_error(const DeltaLight& ours, const DeltaLight& truth, const Image<std::uint8_t>& region) {
  if (!ours.delta.same_shape(truth.delta) || (!region.empty() && !region.same_shape(truth.delta))) {
    ADD_FAILURE() << "the differential images and the region differ in size";
    return {};
  }
  double error = 0.0, total = 0.0, ours_sum = 0.0, truth_sum = 0.0;
  for (std::size_t i = 0; i < truth.delta.size(); ++i) {
    if (ours.covered.data()[i] != 0 || truth.covered.data()[i] != 0) continue;
    if (!region.empty() && region.data()[i] == 0) continue;
    error += std::abs(ours.delta.data()[i] - truth.delta.data()[i]);
    total += std::abs(truth.delta.data()[i]);
    ours_sum += ours.delta.data()[i];
    truth_sum += truth.delta.data()[i];
  }
  if (total <= 0.0) return {};
  return {error / total, ours_sum / truth_sum};
}

double delta_error_against_reference(const std::filesystem::path& frames, int frame,
                                     const std::filesystem::path& reference) {
  const RadianceImage lrv = read_radiance(frame_file(frames, frame, "_L_rv.exr"));
  const RadianceImage lr = read_radiance(frame_file(frames, frame, "_L_r.exr"));
  const ColorImage coverage = read_color(frame_file(frames, frame, "_virtual_coverage.png"));
  const RadianceImage truth_rv = read_radiance(reference);
  auto truth_r_path = reference;
  const RadianceImage truth_r = read_radiance(truth_r_path.replace_extension(".Lr.exr"));
  EXPECT_EQ(truth_rv.width() * 2, lrv.width());
  double error = 0.0, total = 0.0;
  for (int row = 0; row < truth_rv.height(); ++row) {
    for (int col = 0; col < truth_rv.width(); ++col) {
      Eigen::Vector3d ours = Eigen::Vector3d::Zero();
      bool covered = false;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int r = 2 * row + dy, c = 2 * col + dx;
          covered = covered || coverage(r, c).r != 0;
          ours += 0.25 * (Eigen::Vector3d(lrv(r, c).x, lrv(r, c).y, lrv(r, c).z) -
                          Eigen::Vector3d(lr(r, c).x, lr(r, c).y, lr(r, c).z));
        }
      }
      if (covered) continue;
      const Float3 a = truth_rv(row, col), b = truth_r(row, col);
      const Eigen::Vector3d truth(a.x - b.x, a.y - b.y, a.z - b.z);
      error += (ours - truth).cwiseAbs().sum();
      total += truth.cwiseAbs().sum();
    }
  }
  return total > 0.0 ? error / total : 1.0;
}

bool TableView::table_point(int col, int row, Eigen::Vector2d& point) const {
  const Eigen::Vector3d ray = camera_to_world_rotation * Eigen::Vector3d((col - cx) / fx, (row - cy) / fy, 1.0);
  if (std::abs(ray.z()) < 1e-9) return false;
  const double distance = (table_max.z() - camera_position.z()) / ray.z();
  if (distance <= 0.0) return false;
  const Eigen::Vector3d hit = camera_position + distance * ray;
  point = hit.head<2>();
  return (point.array() >= table_min.head<2>().array()).all() && (point.array() <= table_max.head<2>().array()).all();
}

TableView table_view(const std::filesystem::path& sequence, int frame) {
  const auto scene = nlohmann::json::parse(read_text_file(sequence / "scene.json"));
  TableView view;
  const auto& intrinsics = scene["intrinsics"];
  view.fx = intrinsics["fx"];
  view.fy = intrinsics["fy"];
  view.cx = intrinsics["cx"];
  view.cy = intrinsics["cy"];
  for (const auto& object : scene["objects"]) {
    if (object["name"] != "table_top") continue;
    view.table_min = Eigen::Vector3d(object["min"][0], object["min"][1], object["min"][2]);
    view.table_max = Eigen::Vector3d(object["max"][0], object["max"][1], object["max"][2]);
  }
  EXPECT_GT(view.table_max.z(), 0.0) << "scene.json has no table_top";
  std::ifstream trajectory(sequence / "groundtruth.txt");
  std::string line;
  int index = 0;
  while (std::getline(trajectory, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (index++ != frame) continue;
    std::istringstream fields(line);
    double stamp = 0, tx = 0, ty = 0, tz = 0, qx = 0, qy = 0, qz = 0, qw = 1;
    fields >> stamp >> tx >> ty >> tz >> qx >> qy >> qz >> qw;
    view.camera_position = Eigen::Vector3d(tx, ty, tz);
    view.camera_to_world_rotation = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    return view;
  }
  ADD_FAILURE() << sequence << " has no pose for frame " << frame;
  return view;
}

Image<std::uint8_t> shadow_region(const DeltaLight& light, const TableView& view, const Eigen::Vector2d& foot,
                                  double depth, double radius) {
  Image<std::uint8_t> region(light.delta.width(), light.delta.height());
  float deepest = 0.0f;
  for (int pass = 0; pass < 2; ++pass) {  // the deepest value first, then the pixels below the threshold
    for (int row = 0; row < light.delta.height(); ++row) {
      for (int col = 0; col < light.delta.width(); ++col) {
        Eigen::Vector2d point;
        if (light.covered(row, col) != 0 || !view.table_point(col, row, point) || (point - foot).norm() > radius)
          continue;
        const float value = light.delta(row, col);
        if (pass == 0)
          deepest = std::min(deepest, value);
        else if (deepest < 0.0f && value <= static_cast<float>(depth) * deepest)
          region(row, col) = 1;
      }
    }
  }
  return region;
}

ShadowDirection shadow_direction(const DeltaLight& light, const TableView& view, const Eigen::Vector2d& foot,
                                 double depth, double radius) {
  const Image<std::uint8_t> region = shadow_region(light, view, foot, depth, radius);
  struct Sample {
    Eigen::Vector2d point;
    double weight;
  };
  std::vector<Sample> samples;
  double total = 0.0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int row = 0; row < region.height(); ++row) {
    for (int col = 0; col < region.width(); ++col) {
      Eigen::Vector2d point;
      if (region(row, col) == 0 || !view.table_point(col, row, point)) continue;
      samples.push_back({point, -static_cast<double>(light.delta(row, col))});
      total += samples.back().weight;
      centroid += samples.back().weight * point;
    }
  }
  ShadowDirection direction;
  direction.pixels = static_cast<int>(samples.size());
  if (total <= 0.0) return direction;
  centroid /= total;
  Eigen::Matrix2d moments = Eigen::Matrix2d::Zero();
  for (const Sample& s : samples) moments += s.weight * (s.point - centroid) * (s.point - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(moments);
  Eigen::Vector2d axis = solver.eigenvectors().col(1);  // the larger eigenvalue's
  const Eigen::Vector2d offset = centroid - foot;
  if (axis.dot(offset) < 0.0) axis = -axis;
  direction.azimuth_degrees = degrees(std::atan2(offset.y(), offset.x()));
  direction.axis_degrees = degrees(std::atan2(axis.y(), axis.x()));
  direction.centroid_distance = offset.norm();
  return direction;
}

double azimuth_difference(double a_degrees, double b_degrees) {
  const double d = std::fmod(std::abs(a_degrees - b_degrees), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

}  // namespace relight::app::frames_test
