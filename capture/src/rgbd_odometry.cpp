#include "relight/capture/rgbd_odometry.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <list>
#include <vector>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/core/pixel.h"

namespace relight::capture {

namespace {

constexpr int kMaxLevels = 4;

/// One pyramid level of a frame: depth (0 = none) and intensity (0..1), with its intrinsics.
struct Level {
  int width = 0;
  int height = 0;
  float fx = 0, fy = 0, cx = 0, cy = 0;
  std::vector<float> depth;
  std::vector<float> intensity;

  [[nodiscard]] Eigen::Vector3f point(int u, int v, float z) const {
    return {(static_cast<float>(u) - cx) / fx * z, (static_cast<float>(v) - cy) / fy * z, z};
  }
};

/// What an alignment reads of a keyframe level besides its depth and intensity.
struct PreparedLevel {
  std::vector<Eigen::Vector3f> normal;  ///< zero where the surface is not continuous
  std::vector<float> grad_u, grad_v;    ///< central differences of the intensity, per pixel
};

using Pyramid = std::vector<Level>;

float luminance(const Rgb8& c) {
  return (0.299f * c.r + 0.587f * c.g + 0.114f * c.b) * (1.f / 255.f);
}

Level input_level(const DepthMap& depth, const ColorImage& color, const PinholeIntrinsics& k,
                  const RgbdOdometryOptions& options) {
  Level level;
  level.width = depth.width();
  level.height = depth.height();
  level.fx = static_cast<float>(k.fx);
  level.fy = static_cast<float>(k.fy);
  level.cx = static_cast<float>(k.cx);
  level.cy = static_cast<float>(k.cy);
  const std::size_t n = depth.size();
  level.depth.resize(n);
  level.intensity.assign(n, 0.f);
  const float* d = depth.data();
  for (std::size_t i = 0; i < n; ++i) {
    const float z = d[i];
    level.depth[i] = (is_valid_depth(z) && z >= options.min_depth_m && z <= options.max_depth_m) ? z : 0.f;
  }
  if (color.same_shape(depth)) {
    const Rgb8* c = color.data();
    for (std::size_t i = 0; i < n; ++i) level.intensity[i] = luminance(c[i]);
  }
  return level;
}

// 2x2 blocks: the depth is the mean of the samples within 3 % of the nearest one (a block that
// straddles an edge keeps the foreground instead of a point in mid-air); intensity is the mean.
Level half_level(const Level& fine) {
  Level coarse;
  coarse.width = fine.width / 2;
  coarse.height = fine.height / 2;
  coarse.fx = fine.fx * 0.5f;
  coarse.fy = fine.fy * 0.5f;
  coarse.cx = (fine.cx + 0.5f) * 0.5f - 0.5f;
  coarse.cy = (fine.cy + 0.5f) * 0.5f - 0.5f;
  const std::size_t n = static_cast<std::size_t>(coarse.width) * static_cast<std::size_t>(coarse.height);
  coarse.depth.assign(n, 0.f);
  coarse.intensity.assign(n, 0.f);
  for (int v = 0; v < coarse.height; ++v) {
    for (int u = 0; u < coarse.width; ++u) {
      const std::size_t i00 = static_cast<std::size_t>(2 * v) * fine.width + 2 * u;
      const std::size_t idx[4] = {i00, i00 + 1, i00 + fine.width, i00 + fine.width + 1};
      float nearest = std::numeric_limits<float>::max();
      float intensity = 0;
      for (std::size_t i : idx) {
        if (fine.depth[i] > 0.f) nearest = std::min(nearest, fine.depth[i]);
        intensity += fine.intensity[i];
      }
      const std::size_t out = static_cast<std::size_t>(v) * coarse.width + u;
      coarse.intensity[out] = 0.25f * intensity;
      if (nearest == std::numeric_limits<float>::max()) continue;
      float sum = 0;
      int count = 0;
      for (std::size_t i : idx) {
        if (fine.depth[i] > 0.f && fine.depth[i] <= nearest * 1.03f) {
          sum += fine.depth[i];
          ++count;
        }
      }
      coarse.depth[out] = sum / static_cast<float>(count);
    }
  }
  return coarse;
}

Pyramid build_pyramid(const DepthMap& depth, const ColorImage& color, const PinholeIntrinsics& k,
                      const RgbdOdometryOptions& options) {
  Pyramid pyramid;
  pyramid.push_back(input_level(depth, color, k, options));
  for (int l = 1; l < options.levels; ++l) pyramid.push_back(half_level(pyramid.back()));
  return pyramid;
}

// Depth averaged over the 5x5 neighbours that continue the surface (within 4 % + 1 cm of the
// centre): the Kinect's disparity steps make normals of the raw depth tens of degrees wrong,
// and a point-to-plane ICP with such normals slides along the surfaces.
std::vector<float> smoothed_depth(const Level& level) {
  const int w = level.width, h = level.height;
  std::vector<float> out(level.depth.size(), 0.f);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      const float z = level.depth[i];
      if (!(z > 0.f)) continue;
      const float tolerance = 0.04f * z + 0.01f;
      float sum = 0;
      int count = 0;
      for (int dv = -2; dv <= 2; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= h) continue;
        for (int du = -2; du <= 2; ++du) {
          const int uu = u + du;
          if (uu < 0 || uu >= w) continue;
          const float other = level.depth[static_cast<std::size_t>(vv) * w + uu];
          if (other > 0.f && std::abs(other - z) <= tolerance) {
            sum += other;
            ++count;
          }
        }
      }
      out[i] = sum / static_cast<float>(count);
    }
  }
  return out;
}

PreparedLevel prepare(const Level& level) {
  PreparedLevel prepared;
  const int w = level.width, h = level.height;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  prepared.normal.assign(n, Eigen::Vector3f::Zero());
  prepared.grad_u.assign(n, 0.f);
  prepared.grad_v.assign(n, 0.f);
  const std::vector<float> depth = smoothed_depth(level);
  // A neighbour continues the surface when its depth is within 4 % (plus 1 cm) of the centre.
  const auto continues = [](float centre, float other) {
    return other > 0.f && std::abs(other - centre) <= 0.04f * centre + 0.01f;
  };
  for (int v = 1; v + 1 < h; ++v) {
    for (int u = 1; u + 1 < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      prepared.grad_u[i] = 0.5f * (level.intensity[i + 1] - level.intensity[i - 1]);
      prepared.grad_v[i] = 0.5f * (level.intensity[i + w] - level.intensity[i - w]);
      const float z = depth[i];
      if (!(z > 0.f)) continue;
      const float zl = depth[i - 1], zr = depth[i + 1], zu = depth[i - w], zd = depth[i + w];
      if (!continues(z, zl) || !continues(z, zr) || !continues(z, zu) || !continues(z, zd)) continue;
      const Eigen::Vector3f du = level.point(u + 1, v, zr) - level.point(u - 1, v, zl);
      const Eigen::Vector3f dv = level.point(u, v + 1, zd) - level.point(u, v - 1, zu);
      Eigen::Vector3f normal = du.cross(dv);
      const float length = normal.norm();
      if (!(length > 0.f)) continue;
      normal /= length;
      if (normal.dot(level.point(u, v, z)) > 0.f) normal = -normal;  // towards the camera
      prepared.normal[i] = normal;
    }
  }
  return prepared;
}

/// Kinect v1 axial noise (Nguyen, Izadi, Lovell 2012), metres.
float depth_sigma(float z) { return 0.0012f + 0.0019f * (z - 0.4f) * (z - 0.4f); }

/// The normal equations of one Gauss-Newton step, plus the statistics of its residuals.
struct Normal6 {
  Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  double squared = 0;              ///< sum of squared (normalised) geometric residuals of inliers
  double photometric_squared = 0;  ///< sum of squared (normalised) photometric residuals
  std::int64_t photometric_count = 0;
  std::int64_t valid = 0;
  std::int64_t inliers = 0;

  void add(const Normal6& other) {
    h += other.h;
    b += other.b;
    squared += other.squared;
    photometric_squared += other.photometric_squared;
    photometric_count += other.photometric_count;
    valid += other.valid;
    inliers += other.inliers;
  }
};

/// Accumulates one row's residuals in float (a row is at most 640 pixels; the rows are summed in
/// double): the 21 entries of the upper triangle of J^T W J and the 6 of J^T W r, written out so
/// that the compiler keeps them in registers.
struct RowAccumulator {
  std::array<float, 21> h{};
  std::array<float, 6> b{};
  double squared = 0, photometric_squared = 0;
  std::int64_t valid = 0, inliers = 0, photometric_count = 0;

  void add(const std::array<float, 6>& j, float r, float w) {
    int k = 0;
    for (int row = 0; row < 6; ++row) {
      const float wj = w * j[static_cast<std::size_t>(row)];
      for (int col = row; col < 6; ++col) h[static_cast<std::size_t>(k++)] += wj * j[static_cast<std::size_t>(col)];
      b[static_cast<std::size_t>(row)] += wj * r;
    }
  }
  void flush_into(Normal6& total) const {
    int k = 0;
    for (int row = 0; row < 6; ++row) {
      for (int col = row; col < 6; ++col) {
        const double value = h[static_cast<std::size_t>(k++)];
        total.h(row, col) += value;
        if (col != row) total.h(col, row) += value;
      }
      total.b(row) += b[static_cast<std::size_t>(row)];
    }
    total.squared += squared;
    total.photometric_squared += photometric_squared;
    total.photometric_count += photometric_count;
    total.valid += valid;
    total.inliers += inliers;
  }
};

float huber_weight(float r, float k) {
  const float a = std::abs(r);
  return a <= k ? 1.f : k / a;
}

/// The noise scales the residuals are divided by: the Kinect depth model times `geometric`, and
/// `photometric` intensity units. They follow the residuals (see align), so that the two terms
/// weigh by how well each fits this frame, as OpenCV's RGB-D odometry re-estimates its sigma.
struct Scales {
  float geometric = 1;
  float photometric = 0.025f;
};

/// One keyframe level the current frame is aligned against, at transform key_from_current.
struct Reference {
  const Level* key = nullptr;
  const PreparedLevel* prepared = nullptr;
  Eigen::Isometry3f key_from_current = Eigen::Isometry3f::Identity();
};

/// Adds the residuals of one linearisation of the alignment of `current` to `reference` to the
/// per-row systems. The perturbation is on the right (T_key_from_current <- T exp(xi), xi in the
/// current camera's frame), so alignments against several keyframes share one xi: with
/// Q = T P, dQ/dxi = R [I | -[P]x], and a residual with gradient g (in the keyframe) has the
/// Jacobian [R^T g, P x R^T g].
void linearise(const Level& current, const Reference& reference, float max_distance,
               const RgbdOdometryOptions& options, const Scales& scales, bool photometric, int threads, int stride,
               std::vector<Normal6>& rows) {
  const Level& key = *reference.key;
  const PreparedLevel& prepared = *reference.prepared;
  const Eigen::Matrix3f rotation = reference.key_from_current.linear();
  const Eigen::Matrix3f rotation_t = rotation.transpose();
  const Eigen::Vector3f translation = reference.key_from_current.translation();
  const int w = current.width, h = current.height;
  const int kw = key.width, kh = key.height;
  const float inv_sigma_i = 1.f / scales.photometric;
  const float max_distance_sq = max_distance * max_distance;
  parallel_rows(
      h, threads,
      [&](int row_begin, int row_end) {
        for (int v = row_begin; v < row_end; ++v) {
          if (v % stride != 0) continue;
          RowAccumulator acc;
          for (int u = (v / stride) % stride; u < w; u += stride) {
            const std::size_t i = static_cast<std::size_t>(v) * w + u;
            const float z = current.depth[i];
            if (!(z > 0.f)) continue;
            ++acc.valid;
            const Eigen::Vector3f p = current.point(u, v, z);
            const Eigen::Vector3f q = rotation * p + translation;
            if (!(q.z() > 0.f)) continue;
            const float inv_z = 1.f / q.z();
            const float uq = key.fx * q.x() * inv_z + key.cx;
            const float vq = key.fy * q.y() * inv_z + key.cy;
            if (!(uq > -0.5f && vq > -0.5f && uq < static_cast<float>(kw) - 0.5f && vq < static_cast<float>(kh) - 0.5f)) {
              continue;
            }
            const int iu = static_cast<int>(uq + 0.5f);
            const int iv = static_cast<int>(vq + 0.5f);
            const std::size_t k = static_cast<std::size_t>(iv) * kw + iu;
            const Eigen::Vector3f& normal = prepared.normal[k];
            const float zk = key.depth[k];
            if (!(zk > 0.f) || normal.isZero()) continue;
            const Eigen::Vector3f diff = q - key.point(iu, iv, zk);
            if (diff.squaredNorm() > max_distance_sq) continue;
            const float inv_sigma_z = 1.f / (scales.geometric * depth_sigma(q.z()));
            const float rg = normal.dot(diff) * inv_sigma_z;
            const Eigen::Vector3f nc = rotation_t * normal * inv_sigma_z;
            const Eigen::Vector3f nm = p.cross(nc);
            acc.add({nc.x(), nc.y(), nc.z(), nm.x(), nm.y(), nm.z()}, rg, huber_weight(rg, options.huber_k));
            acc.squared += static_cast<double>(rg) * rg;
            ++acc.inliers;
            if (!photometric) continue;
            // Bilinear intensity and gradient of the keyframe at (uq, vq).
            const int u0 = static_cast<int>(uq), v0 = static_cast<int>(vq);
            if (u0 < 1 || v0 < 1 || u0 + 2 >= kw || v0 + 2 >= kh) continue;
            const float au = uq - static_cast<float>(u0), av = vq - static_cast<float>(v0);
            const std::size_t k00 = static_cast<std::size_t>(v0) * kw + u0;
            const auto bilinear = [&](const std::vector<float>& image) {
              return (1 - av) * ((1 - au) * image[k00] + au * image[k00 + 1]) +
                     av * ((1 - au) * image[k00 + kw] + au * image[k00 + kw + 1]);
            };
            const float gu = bilinear(prepared.grad_u), gv = bilinear(prepared.grad_v);
            const float rp = (bilinear(key.intensity) - current.intensity[i]) * inv_sigma_i;
            // grad I . d pi / dQ, in the keyframe, then into the current frame.
            const Eigen::Vector3f g(gu * key.fx * inv_z, gv * key.fy * inv_z,
                                    -(gu * key.fx * q.x() + gv * key.fy * q.y()) * inv_z * inv_z);
            const Eigen::Vector3f gc = rotation_t * g * inv_sigma_i;
            const Eigen::Vector3f gm = p.cross(gc);
            acc.add({gc.x(), gc.y(), gc.z(), gm.x(), gm.y(), gm.z()}, rp, huber_weight(rp, options.huber_k));
            acc.photometric_squared += static_cast<double>(rp) * rp;
            ++acc.photometric_count;
          }
          acc.flush_into(rows[static_cast<std::size_t>(v)]);
        }
      },
      8);
}

Eigen::Isometry3f exp_twist(const Eigen::Matrix<double, 6, 1>& xi) {
  Eigen::Isometry3f step = Eigen::Isometry3f::Identity();
  const Eigen::Vector3d omega = xi.tail<3>();
  const double angle = omega.norm();
  if (angle > 0) step.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix().cast<float>();
  step.translation() = xi.head<3>().cast<float>();
  return step;
}

struct Alignment {
  Pose camera_to_world = Pose::Identity();
  double inlier_ratio = 0;  ///< against the first (nearest) keyframe
  double rms = 0;
  double condition = 0;
};

/// How well a 6x6 system pins the pose: its smallest over its largest eigenvalue (rotations in
/// radians, translations in metres; at the 1-3 m of an indoor scene these weigh alike), so a
/// textureless plane (three free directions) gives ~0.
double condition_of(const Eigen::Matrix<double, 6, 6>& h) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> solver(h, Eigen::EigenvaluesOnly);
  const auto& values = solver.eigenvalues();
  return values(5) > 0 ? std::max(0.0, values(0)) / values(5) : 0.0;
}

}  // namespace

/// Keyframes whose derived data (normals, intensity gradients: 20 bytes a pixel at the levels the
/// alignment reads) is kept; the others rebuild it when they are aligned against again.
constexpr int kPreparedKeyframes = 8;

struct Keyframe {
  int id = 0;
  Pose camera_to_world = Pose::Identity();
  Pyramid pyramid;
  std::vector<PreparedLevel> prepared;  ///< built when first aligned against, dropped when idle
  std::uint64_t last_used = 0;

  /// The pyramids: what the model budget counts (the derived data is a cache of 8 keyframes).
  [[nodiscard]] std::size_t pyramid_bytes() const {
    std::size_t total = 0;
    for (const Level& level : pyramid) total += (level.depth.capacity() + level.intensity.capacity()) * sizeof(float);
    return total;
  }
};

struct RgbdOdometry::State {
  std::list<Keyframe> keyframes;
  int next_id = 0;
  std::uint64_t clock = 0;
  Pose first_pose = Pose::Identity();
  bool started = false;
  Pose last_good = Pose::Identity();
  Pose velocity = Pose::Identity();  ///< last_good_previous^-1 * last_good
  bool lost = false;
  int frames_since_good = 1;  ///< the motion bound grows with the frames the camera was lost
  std::optional<Timestamp> good_time;  ///< of the last good frame, when timestamps are given

  const std::vector<PreparedLevel>& prepared(Keyframe& key, int finest_level) {
    if (key.prepared.empty()) {
      for (std::size_t l = 0; l < key.pyramid.size(); ++l) {
        // Levels finer than the alignment uses are never read.
        key.prepared.push_back(static_cast<int>(l) >= finest_level ? prepare(key.pyramid[l]) : PreparedLevel{});
      }
    }
    key.last_used = ++clock;
    // Keep derived data of a handful of recently used keyframes only.
    int kept = 0;
    std::vector<Keyframe*> with_prepared;
    for (Keyframe& other : keyframes) {
      if (!other.prepared.empty()) with_prepared.push_back(&other);
    }
    std::sort(with_prepared.begin(), with_prepared.end(),
              [](const Keyframe* a, const Keyframe* b) { return a->last_used > b->last_used; });
    for (Keyframe* other : with_prepared) {
      if (++kept > kPreparedKeyframes) other->prepared.clear();
    }
    return key.prepared;
  }
};

namespace {

/// The nearest rigid transform (rotation re-orthonormalised through its quaternion): poses are
/// chained over thousands of frames, and rounding must not grow into a scale.
Pose rigid(const Pose& pose) {
  Pose out = Pose::Identity();
  out.linear() = Eigen::Quaterniond(pose.linear()).normalized().toRotationMatrix();
  out.translation() = pose.translation();
  return out;
}

/// Pose distance in "degrees": rotation angle plus 1 degree per centimetre.
double pose_distance(const Pose& a, const Pose& b) {
  return rotation_distance_degrees(a, b) + 100.0 * (a.translation() - b.translation()).norm();
}

/// A keyframe the current frame is aligned against, with its derived levels.
struct KeyframeView {
  const Keyframe* key = nullptr;
  const std::vector<PreparedLevel>* prepared = nullptr;
};

/// Aligns the current frame against one or more keyframes at once (frame-to-model: the nearest
/// keyframes together are the model), coarse to fine, from `initial` (camera-to-world).
Alignment align(const Pyramid& current, const std::vector<KeyframeView>& keys, const Pose& initial,
                const RgbdOdometryOptions& options, int threads) {
  Alignment result;
  result.camera_to_world = initial;
  const int finest = std::clamp(options.finest_level, 0, static_cast<int>(current.size()) - 1);
  const bool photometric = options.photometric;
  Scales scales{options.geometric_sigma_scale, options.photometric_sigma};
  std::vector<Normal6> rows;
  for (int l = static_cast<int>(current.size()) - 1; l >= finest; --l) {
    const auto level = static_cast<std::size_t>(l);
    const int iterations = options.iterations[std::min(l, kMaxLevels - 1)];
    const float max_distance = options.max_point_distance_m[std::min(l, kMaxLevels - 1)];
    for (int it = 0; it < iterations; ++it) {
      Normal6 system;
      std::int64_t first_inliers = 0, first_valid = 0;
      // Coarse levels bring the pose near (against the nearest keyframes only); the finest
      // level refines it against the whole model.
      const std::size_t models =
          l == finest ? keys.size() : std::min(keys.size(), static_cast<std::size_t>(std::max(1, options.coarse_model_keyframes)));
      for (std::size_t k = 0; k < models; ++k) {
        Reference reference;
        reference.key = &keys[k].key->pyramid[level];
        reference.prepared = &(*keys[k].prepared)[level];
        reference.key_from_current = (keys[k].key->camera_to_world.inverse() * result.camera_to_world).cast<float>();
        rows.assign(static_cast<std::size_t>(current[level].height), Normal6{});
        linearise(current[level], reference, max_distance, options, scales, photometric, threads,
                  l == finest ? options.finest_stride : 1, rows);
        Normal6 one;
        for (const Normal6& row : rows) one.add(row);  // in row order: the result is schedule-free
        if (k == 0) {
          first_inliers = one.inliers;
          first_valid = one.valid;
        }
        system.add(one);
      }
      if (system.inliers < 12) {
        result.inlier_ratio = 0;
        return result;
      }
      const Eigen::Matrix<double, 6, 1> xi = system.h.ldlt().solve(-system.b);
      if (!xi.allFinite()) return result;
      result.camera_to_world = rigid(result.camera_to_world * exp_twist(xi).cast<double>());
      if (options.adaptive_scales) {
        // A robust scale per term (its RMS), bounded so that neither term takes over alone.
        const double g = std::sqrt(system.squared / static_cast<double>(system.inliers));
        scales.geometric = std::clamp(static_cast<float>(scales.geometric * g), options.geometric_sigma_scale,
                                      20.f * options.geometric_sigma_scale);
        if (system.photometric_count > 0) {
          const double p = std::sqrt(system.photometric_squared / static_cast<double>(system.photometric_count));
          scales.photometric = std::clamp(static_cast<float>(scales.photometric * p), 0.004f, 0.1f);
        }
      }
      const bool last = l == finest && it + 1 == iterations;
      if (last || xi.norm() < options.convergence) {
        result.inlier_ratio = static_cast<double>(first_inliers) / static_cast<double>(std::max<std::int64_t>(first_valid, 1));
        result.rms = std::sqrt(system.squared / static_cast<double>(system.inliers)) * scales.geometric;
        result.condition = condition_of(system.h);
        break;
      }
    }
  }
  return result;
}

}  // namespace

RgbdOdometry::RgbdOdometry(const RgbdOdometryOptions& options) : options_(options), state_(std::make_unique<State>()) {
  if (options_.levels < 1 || options_.levels > kMaxLevels) throw Error("odometry: levels must be 1 to 4");
}
RgbdOdometry::~RgbdOdometry() = default;
RgbdOdometry::RgbdOdometry(RgbdOdometry&&) noexcept = default;
RgbdOdometry& RgbdOdometry::operator=(RgbdOdometry&&) noexcept = default;

std::size_t RgbdOdometry::keyframe_count() const { return state_->keyframes.size(); }

std::size_t RgbdOdometry::model_bytes() const {
  std::size_t total = 0;
  for (const Keyframe& key : state_->keyframes) total += key.pyramid_bytes();
  return total;
}
bool RgbdOdometry::started() const { return state_->started; }

void RgbdOdometry::reset(const Pose& pose) {
  state_ = std::make_unique<State>();
  state_->first_pose = pose;
}

void RgbdOdometry::correct(const Pose& pose) {
  if (!state_->started) {
    state_->first_pose = pose;
    return;
  }
  const Pose correction = pose * state_->last_good.inverse();  // world' <- world
  for (Keyframe& key : state_->keyframes) key.camera_to_world = correction * key.camera_to_world;
  state_->last_good = pose;
}

OdometryResult RgbdOdometry::track(const DepthMap& depth, const ColorImage& color, const PinholeIntrinsics& intrinsics,
                                   const std::optional<Pose>& prior, const std::optional<Timestamp>& timestamp) {
  State& state = *state_;
  const int threads = worker_count(options_.threads);
  Pyramid pyramid = build_pyramid(depth, color, intrinsics, options_);
  const bool has_color = color.same_shape(depth);
  RgbdOdometryOptions options = options_;
  options.photometric = options_.photometric && has_color;

  OdometryResult result;
  const auto add_keyframe = [&](const Pose& pose) {
    Keyframe key;
    key.id = state.next_id++;
    key.camera_to_world = pose;
    key.pyramid = std::move(pyramid);
    key.last_used = ++state.clock;
    state.keyframes.push_back(std::move(key));
    const auto budget = static_cast<std::size_t>(std::max(0.f, options_.model_budget_mb) * 1024.f * 1024.f);
    // The new keyframe stays even when it alone is over the budget (the tracker needs one).
    while (state.keyframes.size() > 1 && model_bytes() > budget) {
      auto oldest = std::min_element(state.keyframes.begin(), std::prev(state.keyframes.end()),
                                     [](const Keyframe& a, const Keyframe& b) { return a.last_used < b.last_used; });
      state.keyframes.erase(oldest);
    }
    return state.keyframes.back().id;
  };

  if (!state.started) {
    std::int64_t valid = 0;
    for (float z : pyramid[0].depth) valid += z > 0.f;
    result.camera_to_world = state.first_pose;
    if (valid < static_cast<std::int64_t>(pyramid[0].depth.size() / 10)) {
      result.quality.failure = "too little depth to start tracking";
      return result;
    }
    state.started = true;
    state.last_good = state.first_pose;
    state.good_time = timestamp;
    result.quality.tracked = true;
    result.quality.inlier_ratio = 1;
    result.quality.condition = 1;
    result.quality.new_keyframe = true;
    result.quality.keyframe = add_keyframe(state.first_pose);
    return result;
  }

  const Pose predicted = prior                                       ? *prior
                         : (options.constant_velocity && !state.lost) ? Pose(state.last_good * state.velocity)
                                                                      : state.last_good;
  // The keyframes by their distance to the prediction (stable: the first of equals stays first).
  std::vector<std::pair<double, Keyframe*>> by_distance;
  Keyframe* recent = nullptr;
  for (Keyframe& key : state.keyframes) {
    by_distance.emplace_back(pose_distance(key.camera_to_world, predicted), &key);
    if (!recent || key.last_used > recent->last_used) recent = &key;
  }
  std::stable_sort(by_distance.begin(), by_distance.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  // Candidates: the keyframe nearest the prediction, then the most recently used one.
  std::vector<Keyframe*> candidates;
  if (!by_distance.empty()) candidates.push_back(by_distance.front().second);
  if (recent && recent != by_distance.front().second) candidates.push_back(recent);

  // Frame periods (1/30 s) since the last good frame: from the timestamps when known.
  const double periods = timestamp && state.good_time
                             ? std::max(1.0, (*timestamp - *state.good_time) * 30.0)
                             : static_cast<double>(state.frames_since_good);
  std::string failure = "no keyframe";
  for (Keyframe* key : candidates) {
    // The model: this keyframe and the nearest others that overlap the prediction.
    std::vector<KeyframeView> views{{key, &state.prepared(*key, options.finest_level)}};
    for (const auto& [distance, other] : by_distance) {
      if (static_cast<int>(views.size()) >= options.model_keyframes || distance > options.model_radius_deg) break;
      if (other != key) views.push_back({other, &state.prepared(*other, options.finest_level)});
    }
    const Alignment alignment = align(pyramid, views, predicted, options, threads);
    const Pose pose = alignment.camera_to_world;
    TrackingQuality quality;
    quality.inlier_ratio = alignment.inlier_ratio;
    quality.rms = alignment.rms;
    quality.condition = alignment.condition;
    quality.keyframe = key->id;
    quality.step_m = (pose.translation() - state.last_good.translation()).norm();
    quality.step_deg = rotation_distance_degrees(state.last_good, pose);
    if (alignment.inlier_ratio < options.min_inlier_ratio) {
      failure = "too few depth pixels align (" + std::to_string(static_cast<int>(100 * alignment.inlier_ratio)) + " %)";
    } else if (alignment.condition < options.min_condition) {
      failure = "the view constrains the pose too little (a plane or a blank wall)";
    } else if (alignment.rms > options.max_rms) {
      failure = "residual too large";
    } else if (quality.step_m > options.max_step_m * periods || quality.step_deg > options.max_step_deg * periods) {
      // Also while lost: a wrong local minimum far from the last good pose must not be taken
      // for a recovery (nothing renders with a pose that jumped); a camera that truly moved
      // away is re-acquired when it comes back, or by a marker.
      failure = "implausible motion";
    } else if (state.lost && alignment.inlier_ratio < options.recovery_min_inlier_ratio) {
      failure = "not yet re-acquired";
    } else {
      quality.tracked = true;
      state.velocity = state.lost ? Pose::Identity() : Pose(state.last_good.inverse() * pose);
      state.last_good = pose;
      state.lost = false;
      state.frames_since_good = 1;
      state.good_time = timestamp;
      // A new keyframe when no stored one is within both thresholds of this pose.
      bool covered = false;
      for (const Keyframe& other : state.keyframes) {
        covered = covered ||
                  (rotation_distance_degrees(other.camera_to_world, pose) <= options.keyframe_angle_deg &&
                   (other.camera_to_world.translation() - pose.translation()).norm() <= options.keyframe_distance_m);
      }
      if (!covered || alignment.inlier_ratio < options.keyframe_min_overlap) {
        quality.new_keyframe = true;
        add_keyframe(pose);
      }
      result.camera_to_world = pose;
      result.quality = quality;
      return result;
    }
    result.quality = quality;
  }
  state.lost = true;
  ++state.frames_since_good;
  state.velocity = Pose::Identity();
  result.camera_to_world = state.last_good;
  result.quality.tracked = false;
  result.quality.failure = failure;
  return result;
}

}  // namespace relight::capture
