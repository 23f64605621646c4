#include "relight/synth/trajectory.h"

#include <cmath>
#include <numbers>

#include "random.h"
#include "relight/core/error.h"

namespace relight::synth {

namespace {

using Eigen::Vector3d;

constexpr double kFps = 30.0;
constexpr double kRadius = 1.5;
constexpr double kHeightAboveTarget = 0.7;
constexpr double kStartAzimuth = -0.6435;  // atan2(-0.9, 1.2): sees the tag side of the table
constexpr double kOrbitRate = 20.0 * std::numbers::pi / 180.0;
constexpr double kHandheldOrbitRate = 6.0 * std::numbers::pi / 180.0;
constexpr std::uint64_t kTrajectoryStream = 0x7472616a656374ULL;

Vector3d orbit_eye(const Scene& scene, double azimuth) {
  return scene.look_at + Vector3d{kRadius * std::cos(azimuth), kRadius * std::sin(azimuth), kHeightAboveTarget};
}

// A damped spring driven by white noise: x'' = -k x - c x' + sigma_a * noise. The stationary
// standard deviation is sigma_a / sqrt(2 c k); critical damping (c = 2 sqrt(k)) avoids wobble.
class Shake {
 public:
  Shake(double stationary_sigma, int dimensions) : dims_(dimensions) {
    sigma_a_ = stationary_sigma * std::sqrt(2.0 * kDamping * kStiffness);
  }
  Vector3d step(std::mt19937_64& rng) {
    const double dt = 1.0 / kFps;
    for (int i = 0; i < 3; ++i) {
      const double noise = detail::gaussian(rng);  // drawn for all axes to keep streams aligned
      if (i >= dims_) continue;
      velocity_[i] += (-kStiffness * offset_[i] - kDamping * velocity_[i]) * dt + sigma_a_ * std::sqrt(dt) * noise;
      offset_[i] += velocity_[i] * dt;
    }
    return offset_;
  }

 private:
  static constexpr double kStiffness = 4.0;
  static constexpr double kDamping = 4.0;
  int dims_;
  double sigma_a_;
  Vector3d offset_ = Vector3d::Zero();
  Vector3d velocity_ = Vector3d::Zero();
};

std::vector<Pose> handheld(int frames, std::uint64_t seed, const Scene& scene) {
  std::mt19937_64 rng(detail::stream_seed(seed, kTrajectoryStream, 0));
  Shake eye_shake(0.05, 3), target_shake(0.03, 3), roll_shake(1.5 * std::numbers::pi / 180.0, 1);
  std::vector<Pose> poses;
  for (int i = 0; i < frames; ++i) {
    const double t = i / kFps;
    const Vector3d eye = orbit_eye(scene, kStartAzimuth + kHandheldOrbitRate * t) + eye_shake.step(rng);
    const Vector3d target = scene.look_at + target_shake.step(rng);
    const double roll = roll_shake.step(rng).x();
    poses.push_back(look_at(eye, target) * Eigen::AngleAxisd(roll, Vector3d::UnitZ()));
  }
  return poses;
}

}  // namespace

Timestamp frame_timestamp(int index) { return 1.0 + index / kFps; }

Pose look_at(const Vector3d& eye, const Vector3d& target, const Vector3d& up) {
  const Vector3d z = (target - eye).normalized();
  const Vector3d x = z.cross(up).normalized();  // camera right
  const Vector3d y = z.cross(x);                // camera down
  Pose pose = Pose::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

std::vector<Pose> make_trajectory(Trajectory trajectory, int frames, std::uint64_t seed, const Scene& scene) {
  if (frames < 0) throw Error("number of frames must not be negative");
  if (trajectory == Trajectory::Handheld) return handheld(frames, seed, scene);
  std::vector<Pose> poses;
  for (int i = 0; i < frames; ++i) {
    const double rate = trajectory == Trajectory::Orbit ? kOrbitRate : 0.0;
    poses.push_back(look_at(orbit_eye(scene, kStartAzimuth + rate * i / kFps), scene.look_at));
  }
  return poses;
}

}  // namespace relight::synth
