// pose/odometry_640x480: markerless camera tracking on real Kinect v1 data with mocap ground
// truth, the 150-frame TUM fr1/rpy slice (fast hand-held rotation, 2 degrees per frame; not
// shipped: $RELIGHT_TRACKING_SEQUENCE, default ../shared/data/tum_fr1_rpy_150 beside the source
// tree). Ours (capture/rgbd_odometry.h, frame-to-keyframes) and OpenCV contrib's RGB-D
// odometries (frame to frame, as the library is meant to be used; compiled in when
// libopencv-contrib-dev is installed, scripts/debian-packages-bench.txt) run in the same
// process, interleaved frame by frame. Fields: ms = our median per frame; ate_cm = RMSE of the
// positions after a rigid alignment to the mocap; rpe_deg / rpe_cm = RMSE of the frame-to-frame
// error; baseline = the library tracker with the lowest ATE, with its figures; "libraries"
// lists every library tracker measured.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench.h"
#include "relight/capture/rgbd_odometry.h"
#include "relight/capture/trajectory_error.h"
#include "relight/capture/tum_sequence.h"
#include "replay.h"

#ifdef RELIGHT_HAVE_OPENCV_RGBD
#include <opencv2/core.hpp>
#include <opencv2/rgbd.hpp>
#endif

namespace {

using namespace relight;
using relight::bench::Json;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

double elapsed_ms(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// One tracker's run over the sequence: a pose and a time per frame.
struct TrackerRun {
  std::string name;
  std::vector<Pose> poses;
  std::vector<double> ms;
  int failed = 0;
  std::function<Pose(const RgbdFrame&, bool first, double& ms, bool& ok)> step;
};

Json figures(const TrackerRun& run, const std::vector<Pose>& truth) {
  const capture::RelativePoseError rpe = capture::relative_pose_error(run.poses, truth);
  Json json;
  json["ms"] = median(run.ms);
  json["ate_cm"] = 100.0 * capture::absolute_trajectory_error(run.poses, truth);
  json["rpe_deg"] = rpe.rotation_deg;
  json["rpe_cm"] = 100.0 * rpe.translation_m;
  json["failed_frames"] = run.failed;
  return json;
}

#ifdef RELIGHT_HAVE_OPENCV_RGBD
/// A frame-to-frame OpenCV odometry: compute(previous, current) gives Rt taking points of the
/// previous frame into the current one; the current pose is previous_pose * Rt^-1.
TrackerRun opencv_tracker(const std::string& name, cv::Ptr<cv::rgbd::Odometry> odometry) {
  TrackerRun run;
  run.name = name;
  struct State {
    cv::Mat gray, depth;
    Pose pose = Pose::Identity();
  };
  auto state = std::make_shared<State>();
  run.step = [odometry, state](const RgbdFrame& frame, bool first, double& ms, bool& ok) {
    const int w = frame.depth.width(), h = frame.depth.height();
    cv::Mat gray(h, w, CV_8U), depth(h, w, CV_32F);
    for (int r = 0; r < h; ++r) {
      for (int c = 0; c < w; ++c) {
        const Rgb8 p = frame.color(r, c);
        gray.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>((299 * p.r + 587 * p.g + 114 * p.b) / 1000);
        const float z = frame.depth(r, c);
        depth.at<float>(r, c) = z > 0.f ? z : std::numeric_limits<float>::quiet_NaN();
      }
    }
    ok = true;
    if (first) {
      state->pose = frame.info.camera_to_world.value_or(Pose::Identity());
    } else {
      cv::Mat rt;
      const auto start = Clock::now();
      ok = odometry->compute(state->gray, state->depth, cv::Mat(), gray, depth, cv::Mat(), rt);
      ms = elapsed_ms(start);
      if (ok) {
        Pose step = Pose::Identity();
        for (int r = 0; r < 4; ++r) {
          for (int c = 0; c < 4; ++c) step.matrix()(r, c) = rt.at<double>(r, c);
        }
        state->pose = state->pose * step.inverse();
      }
    }
    state->gray = gray;
    state->depth = depth;
    return state->pose;
  };
  return run;
}
#endif

Json odometry_640x480(const bench::Options&) {
  const char* env = std::getenv("RELIGHT_TRACKING_SEQUENCE");
  const std::filesystem::path folder =
      env && *env ? std::filesystem::path(env) : app::data_folder() / ".." / ".." / "shared" / "data" / "tum_fr1_rpy_150";
  Json json;
  if (!std::filesystem::exists(folder / "groundtruth.txt")) {
    json["skipped"] = "no tracking sequence at " + folder.string() + " (set RELIGHT_TRACKING_SEQUENCE)";
    return json;
  }
  capture::TumOptions tum;
  tum.intrinsics = PinholeIntrinsics::kinect_v1();  // as replay uses for TUM folders (tum_sequence.h)
  const capture::TumSequence sequence = capture::TumSequence::open(folder, tum);
  const PinholeIntrinsics intrinsics = sequence.intrinsics();

  std::vector<TrackerRun> runs;
  capture::RgbdOdometry ours;
  {
    TrackerRun run;
    run.name = "relight";
    run.step = [&ours, &intrinsics](const RgbdFrame& frame, bool first, double& ms, bool& ok) {
      if (first) ours.reset(frame.info.camera_to_world.value_or(Pose::Identity()));
      const auto start = Clock::now();
      const capture::OdometryResult result = ours.track(frame.depth, frame.color, intrinsics);
      ms = elapsed_ms(start);
      ok = result.quality.tracked;
      return result.camera_to_world;
    };
    runs.push_back(std::move(run));
  }
#ifdef RELIGHT_HAVE_OPENCV_RGBD
  const cv::Mat k = (cv::Mat_<float>(3, 3) << intrinsics.fx, 0, intrinsics.cx, 0, intrinsics.fy, intrinsics.cy, 0, 0, 1);
  runs.push_back(opencv_tracker("cv_rgbd_icp_odometry", cv::makePtr<cv::rgbd::RgbdICPOdometry>(k)));
  runs.push_back(opencv_tracker("cv_rgbd_odometry", cv::makePtr<cv::rgbd::RgbdOdometry>(k)));
  runs.push_back(opencv_tracker("cv_icp_odometry", cv::makePtr<cv::rgbd::ICPOdometry>(k)));
  runs.push_back(opencv_tracker("cv_fast_icp_odometry", cv::makePtr<cv::rgbd::FastICPOdometry>(k)));
#endif
  std::vector<Pose> truth;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const RgbdFrame frame = sequence.load(i);
    if (!frame.info.camera_to_world) continue;
    truth.push_back(*frame.info.camera_to_world);
    for (TrackerRun& run : runs) {  // interleaved: every tracker sees frame i before any sees i + 1
      double ms = 0;
      bool ok = true;
      run.poses.push_back(run.step(frame, truth.size() == 1, ms, ok));
      if (truth.size() > 1) run.ms.push_back(ms);
      run.failed += ok ? 0 : 1;
    }
  }
  const Json mine = figures(runs.front(), truth);
  json["ms"] = mine["ms"];
  Json libraries = Json::object();
  std::string best;  // the library tracker with the lowest ATE
  for (std::size_t r = 1; r < runs.size(); ++r) {
    libraries[runs[r].name] = figures(runs[r], truth);
    if (best.empty() || libraries[runs[r].name]["ate_cm"].get<double>() < libraries[best]["ate_cm"].get<double>()) {
      best = runs[r].name;
    }
  }
  if (!best.empty()) {
    const Json& baseline = libraries[best];
    json["baseline"] = best;
    json["baseline_ms"] = baseline["ms"];
    json["ratio"] = baseline["ms"].get<double>() / std::max(1e-9, mine["ms"].get<double>());
    json["baseline_ate_cm"] = baseline["ate_cm"];
    json["baseline_rpe_deg"] = baseline["rpe_deg"];
  } else {
    json["baseline"] = "none (libopencv-contrib-dev not installed)";
  }
  json["ate_cm"] = mine["ate_cm"];
  json["rpe_deg"] = mine["rpe_deg"];
  json["rpe_cm"] = mine["rpe_cm"];
  json["lost_frames"] = mine["failed_frames"];
  json["keyframes"] = ours.keyframe_count();
  json["model_mb"] = static_cast<double>(ours.model_bytes()) / (1024.0 * 1024.0);
  json["frames"] = truth.size();
  json["sequence"] = folder.filename().string();
  json["libraries"] = libraries;
  return json;
}

RELIGHT_BENCH_CASE("pose/odometry_640x480", odometry_640x480);

}  // namespace
