// synth/frame_640x480: time to ray-cast one 640x480 frame of the synthetic scene (ground truth
// and shaded colour) and apply Kinect v1 noise; the goal is <= 1 s per frame on 2 cores. There
// is no external baseline: the fields break the time down instead.
#include <algorithm>
#include <thread>

#include "bench.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"

namespace {

using namespace relight;
using namespace relight::synth;

bench::Json frame_case(const bench::Options& options) {
  const Scene scene = default_indoor_scene();
  const PinholeIntrinsics intrinsics = PinholeIntrinsics::kinect_v1();
  const auto poses = make_trajectory(Trajectory::Orbit, 30, 0, scene);
  std::size_t next = 0;
  long long valid = 0;
  // Cycle through the orbit so that the timing is not one lucky view.
  const double ms = bench::median_ms(
      [&] {
        const std::size_t i = next++ % poses.size();
        const RenderedFrame frame = render_frame(scene, intrinsics, poses[i], 0);
        const DepthMap noisy = apply_kinect_noise(frame.depth, frame.normals, intrinsics, {}, 1, i, 0);
        const ColorImage color = encode_color(frame.radiance);
        valid = std::count_if(noisy.pixels().begin(), noisy.pixels().end(), is_valid_depth);
        (void)color;
      },
      options.repetitions);
  const RenderedFrame frame = render_frame(scene, intrinsics, poses[0], 0);
  const double render_ms = bench::median_ms([&] { (void)render_frame(scene, intrinsics, poses[0], 0); },
                                            options.repetitions);
  const double noise_ms = bench::median_ms(
      [&] { (void)apply_kinect_noise(frame.depth, frame.normals, intrinsics, {}, 1, 0, 0); }, options.repetitions);
  return {{"ms", ms},
          {"unit", "ms per frame (render + noise + colour encoding)"},
          {"render_ms", render_ms},
          {"noise_ms", noise_ms},
          {"threads", std::max(1u, std::thread::hardware_concurrency())},
          {"width", intrinsics.width},
          {"height", intrinsics.height},
          {"valid_depth_fraction", static_cast<double>(valid) / (intrinsics.width * intrinsics.height)}};
}

RELIGHT_BENCH_CASE("synth/frame_640x480", frame_case);

}  // namespace
