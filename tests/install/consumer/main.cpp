// Uses two of relight's stages from an installed package: the depth box filter in a frame graph
// of its own (with a source stage of the consumer's), and the renderer's procedural models.
#include <cmath>
#include <cstdio>

#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/reconstruct/depth_box_filter.h"
#include "relight/render/scene/procedural_models.h"

namespace {

/// Writes a depth map with one far pixel in a flat 1 m plane.
class StepDepthSource final : public relight::Stage {
 public:
  [[nodiscard]] std::string name() const override { return "step_depth"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(relight::StageBuilder& builder) override { depth_ = builder.write(relight::kDepth); }
  void run(relight::StageContext& context) override {
    relight::DepthMap& depth = context.get(depth_);
    depth = relight::DepthMap(32, 24, 1.0f);
    depth(12, 16) = 1.5f;
  }

 private:
  relight::Write<relight::DepthMap> depth_;
};

}  // namespace

int main() {
  relight::FrameGraph graph;
  graph.emplace<StepDepthSource>();
  graph.add(relight::reconstruct::make_depth_box_filter_stage(relight::Backend::Cpu, nullptr));
  graph.keep(relight::kDepthSmoothed);
  graph.compile();
  if (!graph.run_frame()) return 1;
  const relight::DepthMap* smoothed = graph.find(relight::kDepthSmoothed);
  if (!smoothed || smoothed->width() != 32) {
    std::fprintf(stderr, "no smoothed depth\n");
    return 1;
  }
  const float centre = (*smoothed)(12, 16);
  const float height = relight::render::bounds(relight::render::make_matte_box()).sizes().y();
  std::printf("smoothed depth at the step %.3f m, matte box %.3f m tall\n", centre, height);
  // The filter pulls the outlier towards its neighbours; the box is 12 cm tall.
  return centre < 1.5f && centre >= 1.0f && std::abs(height - 0.12f) < 1e-4f ? 0 : 1;
}
