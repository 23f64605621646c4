#include "relight/synth/kinect_noise.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/core/parallel.h"
#include "random.h"
#include "relight/core/error.h"

namespace relight::synth {

namespace {

// Distinguishes the noise stream from the trajectory's when both use the same seed.
constexpr std::uint64_t kNoiseStream = 0x6b696e656374ULL;

bool near_discontinuity(const DepthMap& depth, int row, int col, const KinectNoiseOptions& o) {
  const float z = depth(row, col);
  const double threshold = o.edge_threshold_m + o.edge_threshold_rel * z;
  for (int dr = -o.edge_radius_px; dr <= o.edge_radius_px; ++dr) {
    for (int dc = -o.edge_radius_px; dc <= o.edge_radius_px; ++dc) {
      const int r = row + dr, c = col + dc;
      if (!depth.in_bounds(r, c)) continue;
      const float n = depth(r, c);
      if (!is_valid_depth(n) || std::abs(n - z) > threshold) return true;
    }
  }
  return false;
}

bool grazing(const NormalMap& normals, const PinholeIntrinsics& intrinsics, int row, int col, double max_angle_deg) {
  const Float3& n = normals(row, col);
  if (!is_valid_normal(n)) return false;
  const Eigen::Vector3d ray = intrinsics.ray(col, row).normalized();
  const double cosine = std::abs(ray.dot(Eigen::Vector3d(n.x, n.y, n.z).normalized()));
  return cosine < std::cos(max_angle_deg * std::numbers::pi / 180.0);
}

// Depth at a sub-pixel position: bilinear when the four neighbours lie on one surface, the
// nearest pixel otherwise (so that jitter across an edge picks one side, as the sensor does).
float sample_depth(const DepthMap& depth, double u, double v, const KinectNoiseOptions& o) {
  u = std::clamp(u, 0.0, depth.width() - 1.0);
  v = std::clamp(v, 0.0, depth.height() - 1.0);
  const int c0 = std::min(static_cast<int>(u), std::max(0, depth.width() - 2));
  const int r0 = std::min(static_cast<int>(v), std::max(0, depth.height() - 2));
  const int c1 = std::min(c0 + 1, depth.width() - 1), r1 = std::min(r0 + 1, depth.height() - 1);
  const float d[4] = {depth(r0, c0), depth(r0, c1), depth(r1, c0), depth(r1, c1)};
  const auto [lo, hi] = std::minmax({d[0], d[1], d[2], d[3]});
  if (is_valid_depth(lo) && hi - lo <= o.edge_threshold_m + o.edge_threshold_rel * lo) {
    const double fu = u - c0, fv = v - r0;
    return static_cast<float>((1 - fv) * ((1 - fu) * d[0] + fu * d[1]) + fv * ((1 - fu) * d[2] + fu * d[3]));
  }
  return depth(static_cast<int>(std::lround(v)), static_cast<int>(std::lround(u)));
}

float noisy_pixel(const DepthMap& depth, const NormalMap& normals, const PinholeIntrinsics& intrinsics,
                  const KinectNoiseOptions& o, std::mt19937_64& rng, int row, int col) {
  // Always draw the same numbers per pixel, so that options and missing pixels do not shift the
  // random stream of the rest of the row.
  const double drop = detail::uniform(rng);
  const double jitter_u = detail::gaussian(rng), jitter_v = detail::gaussian(rng);
  const double axial = detail::gaussian(rng);
  if (!is_valid_depth(depth(row, col))) return 0.f;
  if (o.edge_dropouts && drop < o.edge_dropout_probability && near_discontinuity(depth, row, col, o)) return 0.f;
  if (grazing(normals, intrinsics, row, col, o.grazing_angle_deg)) return 0.f;
  double z = sample_depth(depth, col + o.lateral_sigma_px * jitter_u, row + o.lateral_sigma_px * jitter_v, o);
  if (!is_valid_depth(static_cast<float>(z))) return 0.f;
  if (o.axial) z += kinect_axial_sigma(z) * axial;
  if (o.quantise) z = quantise_depth(z, o);
  if (!(z >= o.min_depth && z <= o.max_depth)) return 0.f;
  return static_cast<float>(z);
}

}  // namespace

double kinect_axial_sigma(double z) { return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4); }

double quantise_depth(double z, const KinectNoiseOptions& options) {
  if (!(z > 0.0)) return 0.0;
  const double bf = options.baseline_m * options.focal_px;
  const double disparity = std::round(bf / z / options.subpixel) * options.subpixel;
  return disparity > 0.0 ? bf / disparity : 0.0;
}

DepthMap apply_kinect_noise(const DepthMap& depth, const NormalMap& normals, const PinholeIntrinsics& intrinsics,
                            const KinectNoiseOptions& options, std::uint64_t seed, std::uint64_t frame, int threads) {
  if (!normals.same_shape(depth)) throw Error("apply_kinect_noise: depth and normals differ in size");
  DepthMap noisy(depth.width(), depth.height());
  parallel_for_each_row(depth.height(), threads, [&](int row) {
    std::mt19937_64 rng(detail::stream_seed(seed, kNoiseStream ^ detail::mix(frame), static_cast<std::uint64_t>(row)));
    for (int col = 0; col < depth.width(); ++col) {
      noisy(row, col) = noisy_pixel(depth, normals, intrinsics, options, rng, row, col);
    }
  });
  return noisy;
}

}  // namespace relight::synth
