#include "frame_producer.h"

#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>

#include "relight/capture/depth_millimetres.h"
#include "relight/capture/tum_sequence.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"
#include "relight/synth/trajectory.h"

namespace relight::openni_driver {

namespace {

ProducedFrame pack(std::int64_t index, std::uint64_t timestamp_us, const DepthMap& depth, const ColorImage& color) {
  ProducedFrame frame;
  frame.index = index;
  frame.timestamp_us = timestamp_us;
  frame.size = {depth.width(), depth.height()};
  frame.depth.resize(static_cast<std::size_t>(depth.width()) * static_cast<std::size_t>(depth.height()));
  for (std::size_t i = 0; i < frame.depth.size(); ++i) frame.depth[i] = capture::depth_to_millimetres(depth.data()[i]);
  frame.rgb.resize(frame.depth.size() * 3);
  for (std::size_t i = 0; i < frame.depth.size(); ++i) {
    const Rgb8 c = color.data()[i];
    frame.rgb[3 * i] = c.r;
    frame.rgb[3 * i + 1] = c.g;
    frame.rgb[3 * i + 2] = c.b;
  }
  return frame;
}

std::pair<float, float> fov_of(const PinholeIntrinsics& k) {
  return {static_cast<float>(2.0 * std::atan(k.width / (2.0 * k.fx))),
          static_cast<float>(2.0 * std::atan(k.height / (2.0 * k.fy)))};
}

// synth::default_indoor_scene() seen along a synth trajectory of `loop` frames, which repeats.
// Frame i is exactly what `relight synth` (noise none) renders for frame i mod loop; timestamps
// continue 1 s + i / fps, as synth's frame_timestamp at 30 fps.
class SyntheticProducer final : public FrameProducer {
 public:
  explicit SyntheticProducer(const DeviceUri& uri)
      : uri_(uri), scene_(synth::default_indoor_scene()),
        poses_(synth::make_trajectory(synth::parse_trajectory(uri.trajectory), uri.loop, uri.seed, scene_)) {
    if (uri.width != 0) {
      const Resolution requested{uri.width, uri.height};
      const auto all = resolutions();
      if (std::find(all.begin(), all.end(), requested) == all.end()) {
        throw Error("device URI " + uri.text + ": size must be 640x480 or 320x240");
      }
    }
  }

  std::vector<Resolution> resolutions() const override {
    std::vector<Resolution> all{{640, 480}, {320, 240}};
    if (uri_.width != 0 && Resolution{uri_.width, uri_.height} == all[1]) std::swap(all[0], all[1]);
    return all;
  }

  ProducedFrame produce(std::int64_t index, Resolution size) const override {
    const int loop_index = static_cast<int>(index % uri_.loop);
    const bool cache = cacheable(size);
    if (cache) {
      if (const auto hit = cache_.find({loop_index, size.width}); hit != cache_.end()) {
        ProducedFrame frame = hit->second;
        frame.index = index;
        frame.timestamp_us = timestamp_us(index);
        return frame;
      }
    }
    ProducedFrame frame = render(index, size);
    if (cache) cache_.emplace(std::make_pair(loop_index, size.width), frame);
    return frame;
  }

  ProducedFrame render(std::int64_t index, Resolution size) const {
    const PinholeIntrinsics k = intrinsics(size);
    const auto pose_index = static_cast<std::size_t>(index % uri_.loop);
    const synth::RenderedFrame rendered = synth::render_frame(scene_, k, poses_[pose_index]);
    const DepthMap depth = uri_.noise ? synth::apply_kinect_noise(rendered.depth, rendered.normals, k, {}, uri_.seed,
                                                                  static_cast<std::uint64_t>(index))
                                      : rendered.depth;
    return pack(index, timestamp_us(index), depth, synth::encode_color(rendered.radiance));
  }

  std::uint64_t timestamp_us(std::int64_t index) const override {
    return static_cast<std::uint64_t>(std::llround(1e6 * (1.0 + static_cast<double>(index) / uri_.fps)));
  }

  std::pair<float, float> field_of_view(Resolution size) const override { return fov_of(intrinsics(size)); }
  std::string name() const override { return "relight synthetic RGB-D (" + uri_.trajectory + ")"; }
  std::string serial() const override { return "synthetic-" + std::to_string(uri_.seed); }

  ~SyntheticProducer() override {
    std::error_code ignored;
    if (!scene_folder_.empty()) std::filesystem::remove_all(scene_folder_, ignored);
  }

  // What `relight synth` writes besides the frames (scene.json, probe.hdr), in a folder of its
  // own under the temporary directory; made on the first call (the probe takes a moment).
  std::string scene_folder() const override {
    std::lock_guard lock(scene_folder_mutex_);
    if (!scene_folder_.empty()) return scene_folder_.string();
    std::string pattern = (std::filesystem::temp_directory_path() / "relight-device-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) return "";
    const std::filesystem::path folder = pattern;
    synth::SynthOptions options;
    options.width = resolutions().front().width;
    options.height = resolutions().front().height;
    options.trajectory = synth::parse_trajectory(uri_.trajectory);
    options.seed = uri_.seed;
    write_radiance(folder / "probe.hdr", synth::render_probe(scene_, synth::default_probe(scene_), options.threads));
    write_file_atomically(folder / "scene.json", synth::scene_json(scene_, options));
    scene_folder_ = folder;
    return scene_folder_.string();
  }

 private:
  static PinholeIntrinsics intrinsics(Resolution size) {
    synth::SynthOptions options;
    options.width = size.width;
    options.height = size.height;
    return synth::synth_intrinsics(options);
  }

  // A short loop is rendered once and then replayed from memory, so that after the first pass the
  // device runs at its frame rate however slow the renderer is (1.2 MB a 640x480 frame).
  bool cacheable(Resolution size) const {
    constexpr std::size_t kCacheBytes = std::size_t{256} << 20;
    const std::size_t frame_bytes = static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height) * 5;
    return static_cast<std::size_t>(uri_.loop) * frame_bytes <= kCacheBytes;
  }

  DeviceUri uri_;
  synth::Scene scene_;
  std::vector<Pose> poses_;
  // (loop index, width) -> frame; only the device's frame thread calls produce().
  mutable std::map<std::pair<int, int>, ProducedFrame> cache_;
  mutable std::mutex scene_folder_mutex_;
  mutable std::filesystem::path scene_folder_;
};

// A TUM RGB-D folder, looping. Timestamps are the folder's depth timestamps; each further pass
// adds the folder's duration plus one mean frame period, so time keeps increasing.
class TumProducer final : public FrameProducer {
 public:
  explicit TumProducer(const DeviceUri& uri) : uri_(uri), sequence_(capture::TumSequence::open(uri.folder)) {
    if (sequence_.size() == 0) throw Error("device URI " + uri.text + ": " + uri.folder.string() + " has no frames");
    const double first = sequence_.frame(0).depth_timestamp, last = sequence_.frame(sequence_.size() - 1).depth_timestamp;
    const double period = sequence_.size() > 1 ? (last - first) / static_cast<double>(sequence_.size() - 1) : 1.0 / uri.fps;
    loop_seconds_ = last - first + period;
    const RgbdFrame probe = sequence_.load(0);
    size_ = {probe.depth.width(), probe.depth.height()};
    if (uri.width != 0 && !(Resolution{uri.width, uri.height} == size_)) {
      throw Error("device URI " + uri.text + ": the folder's images are " + std::to_string(size_.width) + "x" +
                  std::to_string(size_.height));
    }
  }

  std::vector<Resolution> resolutions() const override { return {size_}; }

  ProducedFrame produce(std::int64_t index, Resolution) const override {
    const RgbdFrame frame = sequence_.load(static_cast<std::size_t>(index) % sequence_.size());
    if (!(Resolution{frame.depth.width(), frame.depth.height()} == size_) || !frame.color.same_shape(frame.depth)) {
      throw Error(uri_.folder.string() + ": frame " + std::to_string(index % static_cast<std::int64_t>(sequence_.size())) +
                  " is not " + std::to_string(size_.width) + "x" + std::to_string(size_.height));
    }
    return pack(index, timestamp_us(index), frame.depth, frame.color);
  }

  std::uint64_t timestamp_us(std::int64_t index) const override {
    const auto n = static_cast<std::int64_t>(sequence_.size());
    const std::int64_t loops_done = index / n;  // whole loops before this frame
    const double t = sequence_.frame(static_cast<std::size_t>(index % n)).depth_timestamp +
                     static_cast<double>(loops_done) * loop_seconds_;
    return static_cast<std::uint64_t>(std::llround(t * 1e6));
  }

  std::pair<float, float> field_of_view(Resolution) const override { return fov_of(sequence_.intrinsics()); }
  std::string name() const override { return "relight TUM folder " + uri_.folder.filename().string(); }
  std::string serial() const override { return "tum-" + uri_.folder.filename().string(); }
  // A folder of `relight synth` (or one with a probe) already is a scene folder.
  std::string scene_folder() const override {
    const bool has_scene = std::filesystem::exists(uri_.folder / "scene.json") ||
                           std::filesystem::exists(uri_.folder / "probe.hdr");
    return has_scene ? std::filesystem::absolute(uri_.folder).string() : "";
  }

 private:
  DeviceUri uri_;
  capture::TumSequence sequence_;
  Resolution size_;
  double loop_seconds_ = 1.0;
};

}  // namespace

std::unique_ptr<FrameProducer> make_producer(const DeviceUri& uri) {
  if (uri.kind == DeviceUri::Kind::Tum) return std::make_unique<TumProducer>(uri);
  return std::make_unique<SyntheticProducer>(uri);
}

}  // namespace relight::openni_driver
