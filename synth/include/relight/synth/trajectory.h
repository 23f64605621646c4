#pragma once
// Camera paths around the table. Poses are camera-to-world (p_world = pose * p_camera, the TUM
// groundtruth.txt convention), camera frame x right, y down, z forward; world z up.
//   static:   every frame at the start pose, 1.5 m from the table centre, 0.7 m above it;
//   orbit:    circles the table centre at 20 degrees per second, same radius and height;
//   handheld: a slow orbit (6 degrees per second) plus smooth random shake of the eye (~5 cm),
//             of the aim point (~3 cm) and of the roll (~1.5 degrees), from the seed: damped
//             random accelerations (an Ornstein-Uhlenbeck process), so motion is smooth.
// Frame i is taken at 1.0 + i / 30 seconds.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "relight/core/named_values.h"
#include "relight/core/pose.h"
#include "relight/synth/scene.h"

namespace relight::synth {

enum class Trajectory { Static, Orbit, Handheld };
inline constexpr std::array<NamedValue<Trajectory>, 3> kTrajectoryNames{
    {{"static", Trajectory::Static}, {"orbit", Trajectory::Orbit}, {"handheld", Trajectory::Handheld}}};

/// One of kTrajectoryNames; throws relight::Error naming the choices otherwise.
[[nodiscard]] inline Trajectory parse_trajectory(const std::string& name) {
  return parse_named(kTrajectoryNames, "trajectory", name);
}
[[nodiscard]] inline const char* to_string(Trajectory trajectory) { return name_of(kTrajectoryNames, trajectory); }

[[nodiscard]] Timestamp frame_timestamp(int index);

/// Camera at `eye` looking at `target`, image up roughly along `up`.
[[nodiscard]] Pose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                           const Eigen::Vector3d& up = world_up());

/// Poses for frames 0..frames-1, aimed at scene.look_at. The seed only affects `handheld`.
[[nodiscard]] std::vector<Pose> make_trajectory(Trajectory trajectory, int frames, std::uint64_t seed,
                                                const Scene& scene);

}  // namespace relight::synth
