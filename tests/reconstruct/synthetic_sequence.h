#pragma once
// Small synthetic RGB-D sequences for the geometry tests, rendered in memory: exact depth and
// normals from the ray caster (the oracle) and Kinect v1 noisy depth from synth::apply_kinect_noise.
// 320x240 keeps a 10-frame sequence well under a second per test on two cores.
#include <functional>
#include <vector>

#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"
#include "relight/synth/trajectory.h"

namespace relight::test {

struct SyntheticFrame {
  Pose camera_to_world;
  DepthMap noisy;        ///< what the sensor delivers
  DepthMap true_depth;   ///< exact
  NormalMap true_normals;
};

struct SyntheticSequence {
  PinholeIntrinsics intrinsics;
  std::vector<SyntheticFrame> frames;
};

/// `scene_for_frame` lets a test move objects between frames (default: the indoor scene);
/// `frame_step` keeps every n-th pose of the trajectory (a faster camera).
inline SyntheticSequence render_sequence(synth::Trajectory trajectory, int frames, int width = 320, int height = 240,
                                         const std::function<synth::Scene(int)>& scene_for_frame = {},
                                         int frame_step = 1) {
  synth::SynthOptions options;
  options.width = width;
  options.height = height;
  SyntheticSequence sequence{synth::synth_intrinsics(options), {}};
  const synth::Scene base = synth::default_indoor_scene();
  const auto all_poses = synth::make_trajectory(trajectory, frames * frame_step, 0, base);
  std::vector<Pose> poses;
  for (int i = 0; i < frames; ++i) poses.push_back(all_poses[static_cast<std::size_t>(i * frame_step)]);
  for (int i = 0; i < frames; ++i) {
    const synth::Scene scene = scene_for_frame ? scene_for_frame(i) : base;
    synth::RenderedFrame truth = synth::render_frame(scene, sequence.intrinsics, poses[static_cast<std::size_t>(i)]);
    DepthMap noisy = synth::apply_kinect_noise(truth.depth, truth.normals, sequence.intrinsics, options.kinect, 7,
                                               static_cast<std::uint64_t>(i));
    sequence.frames.push_back(
        {poses[static_cast<std::size_t>(i)], std::move(noisy), std::move(truth.depth), std::move(truth.normals)});
  }
  return sequence;
}

/// Feeds a SyntheticSequence into a frame graph: writes "depth" (the noisy depth) and "frame"
/// (intrinsics and the true camera-to-world pose), and ends the stream after the last frame.
class SequenceSource final : public Stage {
 public:
  explicit SequenceSource(const SyntheticSequence& sequence) : sequence_(sequence) {}
  std::string name() const override { return "source"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override {
    depth_ = b.write<DepthMap>("depth");
    frame_ = b.write<FrameInfo>("frame");
  }
  void run(StageContext& ctx) override {
    const auto i = static_cast<std::size_t>(ctx.frame_index());
    if (i >= sequence_.frames.size()) return ctx.end_of_stream();
    ctx.get(depth_) = sequence_.frames[i].noisy;
    ctx.get(frame_) = FrameInfo{ctx.frame_index(), 0.0, sequence_.frames[i].camera_to_world, sequence_.intrinsics};
  }

 private:
  const SyntheticSequence& sequence_;
  Write<DepthMap> depth_;
  Write<FrameInfo> frame_;
};

}  // namespace relight::test
