#pragma once
// The options of a synthetic RGB-D sequence and its scene.json. truth/sequence_writer.h writes
// the sequence with ground truth:
//   rgb/, depth/, rgb.txt, depth.txt, groundtruth.txt  standard TUM RGB-D (capture/tum_writer.h),
//                                                      depth 16-bit PNG, metres * 5000
//   gt/depth/<t>.exr     exact depth, float32 metres along the optical axis (0 = nothing hit)
//   gt/normals/<t>.exr   camera-frame unit normals facing the camera (RGB = xyz)
//   gt/albedo/<t>.png    k_d, sRGB-encoded 8 bit
//   gt/material/<t>.png  16-bit material index + 1 (0 = nothing hit; see scene.json)
//   probe.hdr            the fisheye light probe (probe.h), linear radiance
//   probe.txt, probe/<t>.hdr, gt/lights/<t>.json   with a light animation: the per-frame probe
//                        stream and the true lights of each frame (SynthOptions::light_animation);
//                        with probe noise, probe.txt and probe/ (each frame's noisy probe)
//   scene.json           intrinsics, depth_scale, world_up, materials, objects, lights,
//                        environment, tag (corners and pose), noise, seed, trajectory, probe
// where <t> is TumWriter::file_name(timestamp) without its extension. Colour and depth come from
// one camera (registered, same intrinsics and pose); light emitters are invisible to it.
// Everything is a pure function of the options: the same options give byte-identical files.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "relight/core/camera.h"
#include "relight/synth/camera_effects.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/light_animation.h"
#include "relight/synth/probe.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/trajectory.h"

namespace relight::synth {

/// Depth PNGs hold metres * kSynthDepthScale (TUM's 5000).
inline constexpr double kSynthDepthScale = 5000.0;

struct SynthOptions {
  int frames = 30;
  Trajectory trajectory = Trajectory::Orbit;
  std::uint64_t seed = 0;
  NoiseModel noise = NoiseModel::Kinect1;
  KinectNoiseOptions kinect;  ///< used when noise == Kinect1
  ColorResponse color;        ///< white-balance gains and exposure of the colour camera
  ColorCameraEffects camera;  ///< the colour camera's blur and noise (camera_effects.h)
  int width = 640;            ///< other sizes scale the Kinect v1 intrinsics
  int height = 480;
  int threads = 0;  ///< 0 = all hardware threads
  bool ground_truth = true;
  bool probe = true;
  /// Real light that changes (light_animation.h). When animated, every frame also has its probe
  /// (probe/<t>.hdr, listed in probe.txt as "timestamp filename") and its true lights
  /// (gt/lights/<t>.json, relight's lights format); probe.hdr is frame 0's.
  LightAnimationOptions light_animation;
  /// The probe camera's sensor noise (add_probe_noise; 0 = none). With noise, every frame has its
  /// own probe in probe.txt as with a light animation.
  double probe_noise = 0.0;
};

/// Kinect v1 intrinsics (PinholeIntrinsics::kinect_v1) scaled to options.width x height.
[[nodiscard]] PinholeIntrinsics synth_intrinsics(const SynthOptions& options);

/// The text of scene.json for this scene and these options.
[[nodiscard]] std::string scene_json(const Scene& scene, const SynthOptions& options);

/// {"lights": [...]} of the scene's lights as scene.json has them, with "power" (colour *
/// intensity): what lights::lights_from_json (and so `relight replay --lights`) reads.
[[nodiscard]] std::string frame_lights_json(const Scene& scene);

/// Throws relight::Error for options that cannot make a sequence (negative frames, size < 2x2,
/// gains or exposure not positive).
void validate_synth_options(const SynthOptions& options);

/// Called after each frame with (frames done, frames total).
using SynthProgress = std::function<void(int, int)>;

}  // namespace relight::synth
