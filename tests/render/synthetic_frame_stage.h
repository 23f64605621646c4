#pragma once
// A source stage for the DIR-stage tests: a view of the synthetic scene per frame (one pose, or
// a list of poses played in turn), written as the reconstruct stages would - colour, camera-frame positions and normals, and the pose -
// optionally with fresh Kinect-like depth noise (sigma = depth_noise * z^2) in every frame. With
// Output::Depth it writes the (noisy) depth instead of positions and normals, for the
// reconstruct stages to turn into geometry as in `relight replay`.
#include <random>
#include <vector>

#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/render/scene/depth_mesh.h"
#include "relight/synth/raycast.h"

namespace relight::render::test {

class SyntheticFrameStage final : public Stage {
 public:
  enum class Output { Geometry, Depth };
  SyntheticFrameStage(PinholeIntrinsics intrinsics, Pose pose, float depth_noise = 0.f,
                      Output output = Output::Geometry)
      : SyntheticFrameStage(intrinsics, std::vector<Pose>{pose}, depth_noise, output) {}
  SyntheticFrameStage(PinholeIntrinsics intrinsics, const std::vector<Pose>& poses, float depth_noise = 0.f,
                      Output output = Output::Geometry)
      : intrinsics_(intrinsics), poses_(poses), depth_noise_(depth_noise), output_(output) {
    for (const Pose& pose : poses_) truths_.push_back(synth::render_frame(synth::default_indoor_scene(), intrinsics, pose));
  }
  [[nodiscard]] std::string name() const override { return "synthetic_frame"; }
  void declare(StageBuilder& builder) override {
    frame_ = builder.write<FrameInfo>("frame");
    color_ = builder.write<ColorImage>("color");
    if (output_ == Output::Depth) {
      depth_ = builder.write<DepthMap>("depth");
      return;
    }
    positions_ = builder.write<PositionMap>("positions");
    normals_ = builder.write<NormalMap>("normals");
  }
  void run(StageContext& context) override {
    const std::size_t view = static_cast<std::size_t>(context.frame_index()) % truths_.size();
    const synth::RenderedFrame& truth = truths_[view];
    DepthMap depth = truth.depth;
    if (depth_noise_ > 0.f) {
      std::mt19937 random(static_cast<unsigned>(context.frame_index()) + 1u);
      for (float& z : depth.pixels())
        if (z > 0.f) z += std::normal_distribution<float>(0.f, depth_noise_ * z * z)(random);
    }
    context.get(frame_) = FrameInfo{context.frame_index(), 0.0, poses_[view], intrinsics_};
    context.get(color_) = synth::encode_color(truth.radiance);
    if (output_ == Output::Depth) {
      context.get(depth_) = std::move(depth);
      return;
    }
    context.get(positions_) = positions_from_depth(depth, intrinsics_);
    context.get(normals_) = truth.normals;
  }

 private:
  PinholeIntrinsics intrinsics_;
  std::vector<Pose> poses_;
  float depth_noise_;
  Output output_;
  std::vector<synth::RenderedFrame> truths_;
  Write<FrameInfo> frame_;
  Write<ColorImage> color_;
  Write<PositionMap> positions_;
  Write<NormalMap> normals_;
  Write<DepthMap> depth_;
};

}  // namespace relight::render::test
