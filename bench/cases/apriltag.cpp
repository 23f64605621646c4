// apriltag/detect_640x480: AprilTag detection + pose on a synthetic 640x480 frame of the tag at
// ~1.6 m, at decimation 1 and 2, with the pose error against the synthetic ground truth. The
// detector runs on every hardware thread; the baseline is the same detector on one thread,
// interleaved, and same_detections says whether both found exactly the same corners.
// default_threads: what the detector uses when not told (one on machines with two threads or
// fewer, where this case measured the one thread faster).
#include <algorithm>
#include <thread>

#include "bench.h"
#include "relight/capture/marker_pose.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/truth/tag_layout.h"
#include "relight/synth/trajectory.h"

namespace {

using relight::bench::Json;

Json detect_case(const relight::bench::Options& options, float decimate) {
  const auto scene = relight::synth::default_indoor_scene();
  const auto intrinsics = relight::PinholeIntrinsics::kinect_v1();
  const Eigen::Vector3d tag = scene.tags.front().centre;
  const relight::Pose truth = relight::synth::look_at(tag + Eigen::Vector3d(-0.9, -0.9, 0.9), tag, {0, 0, 1});
  const auto frame = relight::synth::render_frame(scene, intrinsics, truth);
  const relight::ColorImage color = relight::synth::encode_color(frame.radiance);
  const relight::capture::TagLayout layout = relight::truth::tag_layout(scene);

  relight::capture::TagDetectorOptions detector_options;
  detector_options.decimate = decimate;
  const auto hardware_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  detector_options.threads = hardware_threads;
  relight::capture::TagDetector detector(detector_options);
  detector_options.threads = 1;
  relight::capture::TagDetector one_thread(detector_options);
  std::vector<relight::capture::TagDetection> detections, baseline_detections;
  const relight::bench::Comparison comparison =
      relight::bench::compare_interleaved([&] { detections = detector.detect(color); },
                                          [&] { baseline_detections = one_thread.detect(color); }, options.repetitions);
  Json json = relight::bench::comparison_json(comparison, "apriltag_one_thread");
  json["threads"] = hardware_threads;
  json["default_threads"] = relight::capture::default_tag_detector_threads();
  json["same_detections"] =
      detections.size() == baseline_detections.size() &&
      std::equal(detections.begin(), detections.end(), baseline_detections.begin(),
                 [](const auto& a, const auto& b) { return a.id == b.id && a.corners == b.corners; });
  json["decimate"] = decimate;
  json["tags_found"] = detections.size();
  auto pose = relight::capture::estimate_camera_pose(detections, layout, intrinsics);
  if (pose) {
    json["pose_error_cm_colour_only"] = 100.0 * (pose->camera_to_world.translation() - truth.translation()).norm();
    pose = relight::capture::refine_with_depth(*pose, detections, layout, intrinsics, frame.depth);
    json["pose_error_cm"] = 100.0 * (pose->camera_to_world.translation() - truth.translation()).norm();
    json["pose_error_deg"] = relight::rotation_distance(pose->camera_to_world, truth) * 180.0 / 3.14159265358979;
  }
  return json;
}

RELIGHT_BENCH_CASE("apriltag/detect_640x480", [](const relight::bench::Options& o) { return detect_case(o, 1.0f); });
RELIGHT_BENCH_CASE("apriltag/detect_640x480_decimate2",
                   [](const relight::bench::Options& o) { return detect_case(o, 2.0f); });

}  // namespace
