#include "video_probe_stream.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "relight/core/error.h"

namespace relight::app {

namespace {

class VideoProbeStream final : public lights::ProbeStream {
 public:
  VideoProbeStream(std::string spec, bool camera, const lights::ProbeResponse& response)
      : spec_(std::move(spec)), camera_(camera), response_(response) {
    const bool opened = camera_ ? open_camera() : capture_.open(spec_, cv::CAP_FFMPEG);
    if (!opened || !capture_.isOpened()) {
      throw Error("cannot open the probe " + std::string(camera_ ? "camera " : "video ") + spec_);
    }
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = fps > 0.0 && fps < 1000.0 ? fps : 30.0;
  }

  std::optional<Timestamp> next_timestamp() override {
    if (ended_) return std::nullopt;
    if (camera_) return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    return static_cast<double>(next_) / fps_;
  }
  void advance() override {
    grabbed_ = !ended_ && capture_.grab();
    if (!grabbed_) ended_ = true;
    ++next_;
  }
  lights::ProbeFrame decode() override {
    cv::Mat bgr;
    if (!grabbed_ || !capture_.retrieve(bgr) || bgr.empty()) {
      throw Error("the probe " + std::string(camera_ ? "camera " : "video ") + spec_ +
                  (camera_ ? " delivers no frame (unplugged?)" : " has no frame " + std::to_string(next_ - 1)));
    }
    if (bgr.depth() != CV_8U || (bgr.channels() != 3 && bgr.channels() != 1)) {
      throw Error("the probe " + spec_ + " delivers frames that are not 8-bit colour or grey");
    }
    ColorImage image(bgr.cols, bgr.rows);
    cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, image.data());
    cv::cvtColor(bgr, rgb, bgr.channels() == 3 ? cv::COLOR_BGR2RGB : cv::COLOR_GRAY2RGB);
    lights::LdrProbe ldr = lights::radiance_from_ldr(image, response_);
    lights::ProbeFrame frame;
    frame.timestamp = static_cast<double>(next_ - 1) / fps_;
    frame.name = spec_ + " frame " + std::to_string(next_ - 1);
    frame.radiance = std::move(ldr.radiance);
    frame.clipped_share = ldr.clipped_share;
    return frame;
  }
  bool rewind() override {
    if (camera_ || !capture_.set(cv::CAP_PROP_POS_FRAMES, 0.0)) return false;
    next_ = 0;
    ended_ = false;
    return true;
  }
  lights::ProbeTiming timing() const override {
    return camera_ ? lights::ProbeTiming::Latest : lights::ProbeTiming::Timestamped;
  }
  bool relative_timestamps() const override { return !camera_; }
  std::string describe() const override { return spec_; }

 private:
  bool open_camera() {
    const bool index = std::all_of(spec_.begin(), spec_.end(), [](unsigned char c) { return std::isdigit(c); });
    if (index) return capture_.open(std::stoi(spec_), cv::CAP_V4L2);
    return capture_.open(spec_, cv::CAP_V4L2);
  }

  std::string spec_;
  bool camera_;
  lights::ProbeResponse response_;
  cv::VideoCapture capture_;
  double fps_ = 30.0;
  std::int64_t next_ = 0;
  bool grabbed_ = false;
  bool ended_ = false;
};

}  // namespace

bool is_camera_spec(const std::string& spec) {
  if (spec.rfind("/dev/video", 0) == 0) return true;
  return !spec.empty() && spec.size() < 4 &&
         std::all_of(spec.begin(), spec.end(), [](unsigned char c) { return std::isdigit(c); });
}

std::unique_ptr<lights::ProbeStream> open_video_probe(const std::string& spec, const lights::ProbeResponse& response) {
  const bool camera = is_camera_spec(spec);
  std::error_code ec;
  if (!camera && !std::filesystem::is_regular_file(spec, ec)) {
    throw Error("cannot read the probe " + spec + ": no such file, folder or camera");
  }
  return std::make_unique<VideoProbeStream>(spec, camera, response);
}

std::unique_ptr<lights::ProbeStream> open_probe_input(const std::string& spec, const lights::ProbeResponse& response) {
  if (!is_camera_spec(spec)) {
    if (auto stream = lights::open_probe_stream(spec, response)) return stream;
  }
  return open_video_probe(spec, response);
}

}  // namespace relight::app
