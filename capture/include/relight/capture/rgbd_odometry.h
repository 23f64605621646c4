#pragma once
// Markerless RGB-D camera tracking: dense alignment of each frame, coarse to fine, with a
// geometric and a photometric term, against the stored keyframes nearest its predicted pose
// (frame-to-model: up to `model_keyframes` of them at once, in one least-squares problem).
//
// Keyframes are kept for the whole run (within model_budget_mb), so a camera that comes back to a
// view it has seen (the hand-held sweeps of the TUM rpy sequences, a user looking around a
// table) is tracked against the same references again instead of accumulating frame-to-frame
// drift. A frame becomes a keyframe when no stored one is within `keyframe_angle_deg` and
// `keyframe_distance_m` of it, or when too few of its pixels find a partner.
//
// The alignment minimises, over the twist xi of the current camera (Gauss-Newton, right
// perturbation T_key_from_current <- T exp(xi), so that all keyframes share one xi; Huber
// weights), for every valid current pixel p with point P = unproject(p, depth) and
// Q = T_key_from_current P projected to pixel q of a keyframe:
//   geometric (point-to-plane, projective association, as KinectFusion's ICP):
//     r_g = n_k(q) . (Q - v_k(q)) / (s_g sigma_z(z)),  sigma_z(z) = 0.0012 + 0.0019 (z - 0.4)^2 m
//     (Kinect v1 axial noise, Nguyen et al. 2012), so near surfaces count more than far ones;
//   photometric (as DVO / coloured ICP, where the depth alone is ambiguous: planes, the desk):
//     r_p = (I_k(q) - I_c(p)) / s_p,  J_p = grad I_k(q) . d pi / dQ . dQ / dxi
// with v_k, n_k (from the depth smoothed over 5x5 continuous neighbours), I_k and grad I_k
// computed once per keyframe and level. The scales s_g and s_p follow the RMS of their residuals
// at every step (as OpenCV's RGB-D odometry re-estimates its sigma), so the terms weigh by how
// well each fits the frame. Pairs farther than `max_point_distance_m` (per level) or at depth
// discontinuities of the keyframe are rejected. The solution starts from a constant-velocity
// prediction (or a given prior).
//
// Where it departs from the literature's frame-to-model trackers: no TSDF volume (KinectFusion)
// is fused and ray-cast; the stored keyframes are the model (depth and intensity pyramids, 8 bytes
// a pixel over the levels: 0.8 MB a keyframe at 320x240, 3.3 MB at 640x480) instead of a volume,
// which suits the 2-core machine. The model's memory is a byte budget, not a keyframe count, so
// that it is bounded the same at every frame size (a count of 96 was 300 MB at 640x480 and would
// be 1.2 GB at 1280x960); beyond it the least recently used keyframe goes. On top of it, the 8
// most recently aligned keyframes keep their normals and gradients (20 bytes a pixel more).
//
// Failure is a state, not a wild pose (see TrackingQuality): too few inliers, an ill-conditioned
// system (a blank wall: a point-to-plane system with three free directions and no texture), a
// large residual, or a pose farther from the last good one than a hand-held camera moves in the
// frames since (max_step_*). Then the result is not tracked and the caller holds the last good
// pose; the tracker keeps aligning against the keyframes nearest that pose and takes a pose again
// only when it aligns well (recovery_min_inlier_ratio).
#include <memory>
#include <optional>
#include <string>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"

namespace relight::capture {

struct RgbdOdometryOptions {
  int levels = 4;         ///< pyramid levels below and including the input (640 -> 80 px wide)
  int finest_level = 1;   ///< 0 aligns at the input size; 1 stops at half size (faster, ~same ATE)
  int finest_stride = 2;  ///< the finest level uses every n-th row and column (staggered; same ATE, half the time)
  int iterations[4] = {4, 6, 8, 10};  ///< at most, Gauss-Newton steps per level, finest first
  float max_point_distance_m[4] = {0.04f, 0.06f, 0.10f, 0.15f};
  float min_depth_m = 0.3f;
  float max_depth_m = 4.5f;
  float photometric_sigma = 0.025f;  ///< intensity units (0..1); smaller weighs colour more
  float geometric_sigma_scale = 1.f;  ///< times the Kinect noise model; larger weighs depth less
  bool adaptive_scales = true;        ///< both scales follow the residual RMS per iteration
  float huber_k = 2.0f;              ///< in units of the normalised residual
  /// A new keyframe after this much turn (4 deg: ATE 1.87 cm on the TUM fr1/rpy slice against 2.47 at 6,
  /// 2.2 at 10; more keyframes, each nearer the frames aligned to it).
  float keyframe_angle_deg = 4.f;
  float keyframe_distance_m = 0.06f;
  float keyframe_min_overlap = 0.65f;  ///< inlier share below which the frame becomes a keyframe
  int model_keyframes = 3;             ///< keyframes aligned against together (the nearest ones)
  /// Of those, the ones the levels above the finest align against: the nearest alone brings the
  /// pose near, the finest level refines it against all (TUM fr1/rpy slice, Release: 16.8 ms a
  /// frame and ATE 1.91 cm, against 22.5 ms and 1.87 cm with all three on every level).
  int coarse_model_keyframes = 1;
  float model_radius_deg = 12.f;       ///< farther keyframes (pose distance, 1 cm = 1 deg) are not
  /// The keyframe model's memory; the least recently used keyframes are dropped beyond it. 160 MB:
  /// ~48 keyframes at 640x480 (the TUM fr1/rpy slice makes 46), ~200 at 320x240.
  float model_budget_mb = 160.f;
  // Failure detection.
  float min_inlier_ratio = 0.25f;       ///< of the valid pixels at the finest level
  float recovery_min_inlier_ratio = 0.5f;  ///< while lost, a stricter bar for taking a pose again
  float max_rms = 8.0f;                 ///< normalised residual RMS of the inliers
  float max_step_m = 0.15f;             ///< per 1/30 s (~4.5 m/s) since the last good frame
  float max_step_deg = 20.f;            ///< per 1/30 s since the last good frame
  float min_condition = 1e-4f;          ///< smallest/largest eigenvalue of the geometric J^T J
  double convergence = 2e-4;  ///< a level ends when the step is below this (m, rad)
  bool photometric = true;
  bool constant_velocity = true;
  int threads = 0;  ///< 0: worker_count(0)
};

/// How well one frame aligned; also what report.json and the live view show.
struct TrackingQuality {
  bool tracked = false;
  double inlier_ratio = 0;   ///< share of valid current pixels with an accepted partner
  double rms = 0;            ///< normalised residual RMS of the inliers
  double condition = 0;      ///< smallest / largest eigenvalue of the geometric information
  double step_m = 0;         ///< translation since the last tracked frame
  double step_deg = 0;       ///< rotation since the last tracked frame
  int keyframe = -1;         ///< id of the keyframe aligned against
  bool new_keyframe = false;
  std::string failure;       ///< why the frame did not track ("" when tracked)
};

struct OdometryResult {
  Pose camera_to_world = Pose::Identity();  ///< the tracked pose, or the last good one when lost
  TrackingQuality quality;
};

class RgbdOdometry {
 public:
  explicit RgbdOdometry(const RgbdOdometryOptions& options = {});
  ~RgbdOdometry();
  RgbdOdometry(RgbdOdometry&&) noexcept;
  RgbdOdometry& operator=(RgbdOdometry&&) noexcept;

  /// Tracks one frame. The first frame (or the first after reset) is placed at `first_pose`
  /// (identity by default, see reset) and becomes the first keyframe. `prior`, when given, is
  /// where the alignment starts instead of the constant-velocity prediction (a marker pose).
  /// `timestamp` (seconds), when given, bounds the motion by the time since the last good frame
  /// (max_step_* per 1/30 s) instead of by the frames tracked: a live device drops frames when
  /// the pipeline is slower than the camera.
  OdometryResult track(const DepthMap& depth, const ColorImage& color, const PinholeIntrinsics& intrinsics,
                       const std::optional<Pose>& prior = std::nullopt,
                       const std::optional<Timestamp>& timestamp = std::nullopt);

  /// Forgets every keyframe; the next frame is placed at `pose`.
  void reset(const Pose& pose = Pose::Identity());
  /// An absolute correction from outside (a marker pose): the current pose becomes `pose`, and
  /// the keyframes are moved by the same rigid correction so that the reference stays consistent.
  void correct(const Pose& pose);

  [[nodiscard]] std::size_t keyframe_count() const;
  /// Bytes the keyframe model holds now (the pyramids, which model_budget_mb bounds).
  [[nodiscard]] std::size_t model_bytes() const;
  /// A first frame has been placed (since construction or the last reset).
  [[nodiscard]] bool started() const;
  [[nodiscard]] const RgbdOdometryOptions& options() const { return options_; }

 private:
  struct State;
  RgbdOdometryOptions options_;
  std::unique_ptr<State> state_;
};

}  // namespace relight::capture
