#include "relight/capture/openni_source.h"

#include <OpenNI.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <thread>
#include <utility>

#include "relight/capture/depth_millimetres.h"
#include "relight/capture/relight_device.h"
#include "relight/core/error.h"

namespace relight::capture {

namespace {

// OpenNI2's error log, one line per message with tabs: joined into one line for relight::Error.
std::string extended_error() {
  const char* text = openni::OpenNI::getExtendedError();
  std::string message;
  std::string line;
  auto flush = [&] {
    const auto begin = line.find_first_not_of(" \t"), end = line.find_last_not_of(" \t");
    if (begin != std::string::npos) message += (message.empty() ? "" : "; ") + line.substr(begin, end - begin + 1);
    line.clear();
  };
  for (const char* c = text; c != nullptr && *c != '\0'; ++c) {
    if (*c == '\n' || *c == '\r') {
      flush();
    } else {
      line += *c;
    }
  }
  flush();
  return message;
}

// OpenNI::initialize/shutdown for as long as any user needs it (shutdown unloads the drivers, so
// it must come after every device is closed: holders keep it alive).
class OpenNiRuntime {
 public:
  OpenNiRuntime() {
    if (openni::OpenNI::initialize() != openni::STATUS_OK) {
      throw Error("OpenNI2 did not start: " + extended_error());
    }
  }
  ~OpenNiRuntime() { openni::OpenNI::shutdown(); }
  OpenNiRuntime(const OpenNiRuntime&) = delete;
  OpenNiRuntime& operator=(const OpenNiRuntime&) = delete;

  static std::shared_ptr<OpenNiRuntime> acquire() {
    static std::mutex mutex;
    static std::weak_ptr<OpenNiRuntime> current;
    std::lock_guard lock(mutex);
    auto runtime = current.lock();
    if (!runtime) {
      runtime = std::make_shared<OpenNiRuntime>();
      current = runtime;
    }
    return runtime;
  }
};

// Sets a flag when the device with our URI goes away (called on a driver thread).
class DisconnectWatch final : public openni::OpenNI::DeviceDisconnectedListener {
 public:
  explicit DisconnectWatch(std::string uri) : uri_(std::move(uri)) { openni::OpenNI::addDeviceDisconnectedListener(this); }
  ~DisconnectWatch() override { openni::OpenNI::removeDeviceDisconnectedListener(this); }
  DisconnectWatch(const DisconnectWatch&) = delete;
  DisconnectWatch& operator=(const DisconnectWatch&) = delete;
  void onDeviceDisconnected(const openni::DeviceInfo* info) override {
    if (info != nullptr && uri_ == info->getUri()) disconnected_ = true;
  }
  [[nodiscard]] bool disconnected() const { return disconnected_; }

 private:
  std::string uri_;
  std::atomic<bool> disconnected_{false};
};

constexpr int kWaitSliceMs = 100;

std::string frames_text(std::int64_t count) { return std::to_string(count) + (count == 1 ? " frame" : " frames"); }

std::string one_decimal(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", value);
  return text;
}

bool is_oni_file(const std::string& uri) {
  const std::filesystem::path path(uri);
  return path.extension() == ".oni" || path.extension() == ".ONI";
}

// openni::VideoStream, stopped and destroyed by close() or on scope exit.
struct Stream {
  openni::VideoStream stream;
  Stream() = default;
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  ~Stream() { close(); }
  void close() {
    if (stream.isValid()) {
      stream.stop();
      stream.destroy();
    }
  }
};

// openni::Device, closed by close() or on scope exit.
struct Device {
  openni::Device device;
  Device() = default;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  ~Device() { close(); }
  void close() {
    if (device.isValid()) device.close();
  }
};

void open_device(Device& device, const std::string& uri, bool file) {
  if (file) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(uri, ec)) throw Error(uri + ": no such .oni file");
    if (std::filesystem::file_size(uri, ec) == 0) throw Error(uri + ": empty file, not an .oni recording");
  }
  const char* target = uri.empty() ? openni::ANY_DEVICE : uri.c_str();
  if (device.device.open(target) == openni::STATUS_OK) return;
  const std::string detail = extended_error();
  if (file) {
    // OpenNI2 gives no message for a cut recording (docs/platform.md): say what it most likely is.
    throw Error(uri + ": cannot play this .oni file (truncated or corrupt recording)" +
                (detail.empty() ? std::string() : ": " + detail));
  }
  if (uri.empty()) throw Error("no OpenNI2 device found" + (detail.empty() ? std::string() : ": " + detail));
  throw Error("cannot open OpenNI2 device " + uri + (detail.empty() ? std::string() : ": " + detail));
}

void create_stream(Stream& stream, Device& device, openni::SensorType type, const char* what, const std::string& uri) {
  if (device.device.getSensorInfo(type) == nullptr) throw Error(uri + " has no " + what + " stream");
  if (stream.stream.create(device.device, type) != openni::STATUS_OK) {
    throw Error("cannot create the " + std::string(what) + " stream of " + uri + ": " + extended_error());
  }
}

bool usable_pair(const openni::VideoMode& depth, const openni::VideoMode& color) {
  return depth.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM && color.getPixelFormat() == openni::PIXEL_FORMAT_RGB888 &&
         depth.getResolutionX() == color.getResolutionX() && depth.getResolutionY() == color.getResolutionY() &&
         depth.getFps() == color.getFps();
}

// Keeps the device's default modes when they suit relight (1 mm depth and RGB888 colour of one
// size, as the virtual device and a Kinect give), else picks the largest such pair it supports
// (e.g. an Xtion, whose default depth is 320x240).
void choose_modes(Device& device, openni::VideoStream& depth, openni::VideoStream& color) {
  if (usable_pair(depth.getVideoMode(), color.getVideoMode())) return;
  const auto& depth_modes = device.device.getSensorInfo(openni::SENSOR_DEPTH)->getSupportedVideoModes();
  const auto& color_modes = device.device.getSensorInfo(openni::SENSOR_COLOR)->getSupportedVideoModes();
  int best_depth = -1, best_color = -1, best_pixels = 0;
  for (int d = 0; d < depth_modes.getSize(); ++d) {
    for (int c = 0; c < color_modes.getSize(); ++c) {
      const int pixels = depth_modes[d].getResolutionX() * depth_modes[d].getResolutionY();
      if (usable_pair(depth_modes[d], color_modes[c]) && pixels > best_pixels) {
        best_depth = d;
        best_color = c;
        best_pixels = pixels;
      }
    }
  }
  if (best_depth < 0) return;  // open() reports what is wrong with the defaults
  depth.setVideoMode(depth_modes[best_depth]);
  color.setVideoMode(color_modes[best_color]);
}

}  // namespace

std::vector<OpenNiDeviceInfo> list_openni_devices() {
  const auto runtime = OpenNiRuntime::acquire();
  openni::Array<openni::DeviceInfo> devices;
  openni::OpenNI::enumerateDevices(&devices);
  std::vector<OpenNiDeviceInfo> list;
  for (int i = 0; i < devices.getSize(); ++i) {
    list.push_back({devices[i].getUri(), devices[i].getVendor(), devices[i].getName()});
  }
  return list;
}

OniRecordingSummary inspect_oni(const std::filesystem::path& file) {
  const auto runtime = OpenNiRuntime::acquire();
  Device device;
  open_device(device, file.string(), true);
  Stream depth, color;
  OniRecordingSummary summary;
  openni::PlaybackControl* playback = device.device.getPlaybackControl();
  if (playback == nullptr) throw Error(file.string() + " did not open as a recording");
  if (device.device.hasSensor(openni::SENSOR_COLOR)) {
    create_stream(color, device, openni::SENSOR_COLOR, "colour", file.string());
    summary.color_frames = playback->getNumberOfFrames(color.stream);
  }
  if (!device.device.hasSensor(openni::SENSOR_DEPTH)) return summary;
  create_stream(depth, device, openni::SENSOR_DEPTH, "depth", file.string());
  summary.depth_frames = playback->getNumberOfFrames(depth.stream);
  playback->setRepeatEnabled(false);
  playback->setSpeed(-1.0f);
  // Every stream of the file is read: at speed -1 the player waits for all of them.
  std::vector<openni::VideoStream*> streams{&depth.stream};
  if (color.stream.isValid()) streams.push_back(&color.stream);
  for (openni::VideoStream* stream : streams) {
    if (stream->start() != openni::STATUS_OK) throw Error(file.string() + ": cannot play it: " + extended_error());
  }
  while (static_cast<std::int64_t>(summary.depth_timestamps_us.size()) < summary.depth_frames) {
    int ready = -1;
    openni::VideoFrameRef frame;
    if (openni::OpenNI::waitForAnyStream(streams.data(), static_cast<int>(streams.size()), &ready, 2000) != openni::STATUS_OK ||
        streams[static_cast<std::size_t>(ready)]->readFrame(&frame) != openni::STATUS_OK) {
      throw Error(file.string() + ": the recording ends after " + std::to_string(summary.depth_timestamps_us.size()) +
                  " of " + std::to_string(summary.depth_frames) + " depth frames (truncated or corrupt file)");
    }
    if (ready == 0) summary.depth_timestamps_us.push_back(frame.getTimestamp());
  }
  return summary;
}

struct OpenNiSource::Impl {
  OpenNiOptions options;
  bool file = false;
  std::shared_ptr<OpenNiRuntime> runtime;  // first member: destroyed last, after the device
  std::unique_ptr<Device> device = std::make_unique<Device>();  // replaced on a reconnect
  std::unique_ptr<DisconnectWatch> watch;
  Stream depth, color;
  openni::Recorder recorder;
  std::string uri;  // the device's own URI (for a file: the path)
  std::string name;
  PinholeIntrinsics intrinsics;
  std::int64_t total = 0;
  std::int64_t delivered = 0;
  std::int64_t dropped = 0;
  std::uint64_t half_period_us = 16667;
  std::uint64_t last_timestamp_us = 0;
  /// Host clock minus device clock, the smallest seen: the frame that reached us fastest sets it,
  /// so a frame that waited in a queue shows its wait (capture_time below).
  std::optional<double> host_minus_device;
  int last_depth_index = -1;
  std::optional<openni::VideoFrameRef> pending_depth, pending_color;
  std::vector<DeviceReconnect> reconnects;
  /// Added to the device's timestamps: 0 unless a device came back with its clock restarted.
  std::int64_t timestamp_offset_us = 0;
  std::uint64_t last_output_timestamp_us = 0;
  /// Host time of the last frame next() returned.
  std::chrono::steady_clock::time_point last_frame_time;
  /// Set by reconnect() to last_frame_time: the next frame completes the reconnect.
  std::optional<std::chrono::steady_clock::time_point> unplugged_since;

  void open();
  /// Opens the device, its streams and modes (everything but the intrinsics and the start).
  void connect(const std::string& target);
  void start_streams();
  void close_streams();
  /// Waits for an unplugged device to come back and starts it again; false when stop_waiting
  /// said stop. Throws when it is not back within the reconnect timeout.
  bool reconnect();
  void notice(const std::string& line) const {
    if (options.on_notice) options.on_notice(line);
  }
  [[nodiscard]] RgbdFrame convert(const openni::VideoFrameRef& depth_frame, const openni::VideoFrameRef& color_frame);
  void note_depth_index(int index) {
    if (last_depth_index >= 0 && index > last_depth_index + 1) dropped += index - last_depth_index - 1;
    last_depth_index = index;
  }
};

void OpenNiSource::Impl::open() {
  file = is_oni_file(options.uri);
  runtime = OpenNiRuntime::acquire();
  connect(options.uri);
  const openni::VideoMode depth_mode = depth.stream.getVideoMode();
  if (depth_mode.getFps() > 0) half_period_us = static_cast<std::uint64_t>(500000 / depth_mode.getFps());
  const int width = depth_mode.getResolutionX(), height = depth_mode.getResolutionY();
  if (options.intrinsics) {
    intrinsics = *options.intrinsics;
  } else {
    const double hfov = depth.stream.getHorizontalFieldOfView(), vfov = depth.stream.getVerticalFieldOfView();
    if (!(hfov > 0.0 && vfov > 0.0)) throw Error(uri + ": the depth stream reports no field of view");
    intrinsics = {width / (2.0 * std::tan(hfov / 2.0)),
                  height / (2.0 * std::tan(vfov / 2.0)),
                  (width - 1) / 2.0,
                  (height - 1) / 2.0,
                  width,
                  height};
  }
  start_streams();
}

void OpenNiSource::Impl::connect(const std::string& target) {
  open_device(*device, target, file);
  uri = device->device.getDeviceInfo().getUri();
  name = device->device.getDeviceInfo().getName();
  watch = std::make_unique<DisconnectWatch>(uri);
  create_stream(depth, *device, openni::SENSOR_DEPTH, "depth", uri);
  create_stream(color, *device, openni::SENSOR_COLOR, "colour", uri);
  if (file) {
    // Sequential reads only (seek crashes in OpenNI2 2.2); speed -1: as fast as we read, no repeat.
    openni::PlaybackControl* playback = device->device.getPlaybackControl();
    if (playback == nullptr) throw Error(uri + " did not open as a recording");
    playback->setRepeatEnabled(false);
    playback->setSpeed(-1.0f);
    total = playback->getNumberOfFrames(depth.stream);
  } else {
    if (device->device.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
      device->device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
    }
    device->device.setDepthColorSyncEnabled(true);  // best effort: pairing below works without it
    choose_modes(*device, depth.stream, color.stream);
  }
  const openni::VideoMode depth_mode = depth.stream.getVideoMode(), color_mode = color.stream.getVideoMode();
  if (depth_mode.getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_1_MM) {
    throw Error(uri + ": depth stream is not in millimetres (pixel format " +
                std::to_string(static_cast<int>(depth_mode.getPixelFormat())) + ")");
  }
  if (color_mode.getPixelFormat() != openni::PIXEL_FORMAT_RGB888) {
    throw Error(uri + ": colour stream is not RGB888 (pixel format " +
                std::to_string(static_cast<int>(color_mode.getPixelFormat())) + ")");
  }
  if (depth_mode.getResolutionX() != color_mode.getResolutionX() || depth_mode.getResolutionY() != color_mode.getResolutionY()) {
    throw Error(uri + ": depth " + std::to_string(depth_mode.getResolutionX()) + "x" +
                std::to_string(depth_mode.getResolutionY()) + " and colour " + std::to_string(color_mode.getResolutionX()) +
                "x" + std::to_string(color_mode.getResolutionY()) + " differ; relight needs registered images of one size");
  }
}

void OpenNiSource::Impl::close_streams() {
  depth.close();
  color.close();
  watch.reset();
}

void OpenNiSource::Impl::start_streams() {
  if (depth.stream.start() != openni::STATUS_OK) throw Error("cannot start the depth stream of " + uri + ": " + extended_error());
  if (color.stream.start() != openni::STATUS_OK) throw Error("cannot start the colour stream of " + uri + ": " + extended_error());
}

bool OpenNiSource::Impl::reconnect() {
  using Clock = std::chrono::steady_clock;
  const auto since = Clock::now();
  const std::string gone = "OpenNI2 device " + uri + " disconnected after " + frames_text(delivered);
  const std::string timeout = one_decimal(static_cast<double>(options.reconnect_timeout.count()) / 1000.0) + " s";
  notice(gone + "; waiting up to " + timeout + " for it to come back");
  // The old connection's streams go first: they belong to a device OpenNI2 has dropped (a device
  // plugged back is a new device object in OpenNI2's core).
  pending_depth.reset();
  pending_color.reset();
  close_streams();
  // The old handle stays open until the device is back: a real device does not care, and relight's
  // own device counts down to its return on the unplugged device object (openni_driver/driver.cpp).
  const std::unique_ptr<Device> unplugged = std::exchange(device, std::make_unique<Device>());
  const std::string target = options.uri.empty() ? std::string() : uri;
  const int width = intrinsics.width, height = intrinsics.height;
  while (true) {
    if (options.stop_waiting && options.stop_waiting()) return false;
    try {
      connect(target);
      break;
    } catch (const Error&) {
      // Not back yet (or back but not usable yet): try again until the timeout.
      close_streams();
      device->close();
    }
    if (Clock::now() - since >= options.reconnect_timeout) {
      std::string message = gone;
      throw Error(message.append(" and did not come back within ").append(timeout));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(kWaitSliceMs));
  }
  const openni::VideoMode mode = depth.stream.getVideoMode();
  if (mode.getResolutionX() != width || mode.getResolutionY() != height) {
    throw Error(gone + " and came back with " + std::to_string(mode.getResolutionX()) + "x" +
                std::to_string(mode.getResolutionY()) + " frames instead of " + std::to_string(width) + "x" +
                std::to_string(height));
  }
  start_streams();
  last_depth_index = -1;  // frame indices of the new connection: the time away is not "dropped"
  host_minus_device.reset();
  unplugged_since = last_frame_time;
  reconnects.push_back({delivered, 0.0});
  return true;
}

RgbdFrame OpenNiSource::Impl::convert(const openni::VideoFrameRef& depth_frame, const openni::VideoFrameRef& color_frame) {
  const int width = depth_frame.getWidth(), height = depth_frame.getHeight();
  if (color_frame.getWidth() != width || color_frame.getHeight() != height) {
    throw Error(uri + ": frame " + std::to_string(depth_frame.getFrameIndex()) + " has depth and colour of different sizes");
  }
  RgbdFrame frame;
  frame.depth = DepthMap(width, height);
  frame.color = ColorImage(width, height);
  const auto* depth_bytes = static_cast<const std::uint8_t*>(depth_frame.getData());
  const auto* color_bytes = static_cast<const std::uint8_t*>(color_frame.getData());
  for (int row = 0; row < height; ++row) {
    const std::uint8_t* depth_row = depth_bytes + static_cast<std::size_t>(row) * depth_frame.getStrideInBytes();
    const std::uint8_t* color_row = color_bytes + static_cast<std::size_t>(row) * color_frame.getStrideInBytes();
    for (int col = 0; col < width; ++col) {
      std::uint16_t mm = 0;
      std::memcpy(&mm, depth_row + 2 * col, sizeof(mm));
      frame.depth(row, col) = millimetres_to_depth(mm);
      frame.color(row, col) = {color_row[3 * col], color_row[3 * col + 1], color_row[3 * col + 2]};
    }
  }
  frame.info.index = delivered++;
  const std::uint64_t device_us = depth_frame.getTimestamp();
  const auto now_host = std::chrono::steady_clock::now();
  if (unplugged_since) {
    // The first frame after a reconnect: a device whose clock restarted would send time backwards
    // (tracking, smoothing and the report assume it runs forwards), so its clock is moved to go
    // on from the last frame plus the time away. relight's own device keeps its clock.
    const double away = std::chrono::duration<double>(now_host - *unplugged_since).count();
    reconnects.back().seconds_away = away;
    if (static_cast<std::int64_t>(device_us) + timestamp_offset_us <=
        static_cast<std::int64_t>(last_output_timestamp_us)) {
      timestamp_offset_us = static_cast<std::int64_t>(last_output_timestamp_us) + std::llround(away * 1e6) -
                            static_cast<std::int64_t>(device_us);
    }
    unplugged_since.reset();
    notice("OpenNI2 device " + uri + " is back after " + one_decimal(away) + " s; going on");
  }
  last_frame_time = now_host;
  last_output_timestamp_us = static_cast<std::uint64_t>(static_cast<std::int64_t>(device_us) + timestamp_offset_us);
  frame.info.timestamp = static_cast<double>(last_output_timestamp_us) * 1e-6;
  frame.info.intrinsics = intrinsics;
  last_timestamp_us = device_us;
  if (!file) {
    const double now = std::chrono::duration<double>(now_host.time_since_epoch()).count();
    const double offset = now - frame.info.timestamp;
    if (!host_minus_device || offset < *host_minus_device) host_minus_device = offset;
    frame.info.capture_time = frame.info.timestamp + *host_minus_device;
  }
  return frame;
}

OpenNiSource::OpenNiSource(OpenNiOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->open();
}

OpenNiSource::~OpenNiSource() {
  if (impl_->recorder.isValid()) stop_recording();
}

std::optional<RgbdFrame> OpenNiSource::next() {
  Impl& s = *impl_;
  openni::VideoStream* streams[] = {&s.depth.stream, &s.color.stream};
  const auto timeout = static_cast<int>(s.file ? std::min<std::int64_t>(s.options.timeout.count(), 2000)
                                                : s.options.timeout.count());
  while (true) {
    if (s.file && s.total > 0 && s.delivered >= s.total) return std::nullopt;  // all frames read
    if (s.pending_depth && s.pending_color) {
      const std::uint64_t td = s.pending_depth->getTimestamp(), tc = s.pending_color->getTimestamp();
      const std::uint64_t gap = td > tc ? td - tc : tc - td;
      if (gap <= s.half_period_us) {
        RgbdFrame frame = s.convert(*s.pending_depth, *s.pending_color);
        s.pending_depth.reset();
        s.pending_color.reset();
        return frame;
      }
      (td < tc ? s.pending_depth : s.pending_color).reset();  // the older one has no partner
      ++s.dropped;
    }
    // Waits in short slices: a disconnect does not wake waitForAnyStream, so the listener's flag is
    // checked between slices; once it is set only frames already queued remain.
    int ready = -1;
    openni::Status status = openni::STATUS_TIME_OUT;
    for (int waited = 0; waited < timeout && status == openni::STATUS_TIME_OUT;) {
      const bool gone = s.watch->disconnected();
      const int slice = std::min(kWaitSliceMs, timeout - waited);
      status = openni::OpenNI::waitForAnyStream(streams, 2, &ready, slice);
      waited += slice;
      if (gone) break;  // one more slice after the disconnect was seen, for frames in flight
    }
    if (status == openni::STATUS_TIME_OUT) {
      if (s.file) {
        // The end of a recording shows only as a timeout; before the frame count it is a cut file.
        if (s.delivered < s.total) {
          throw Error(s.uri + ": the recording ends after " + std::to_string(s.delivered) + " of " +
                      std::to_string(s.total) + " frames (truncated or corrupt file)");
        }
        return std::nullopt;
      }
      if (s.watch->disconnected()) {
        // A .oni recording cannot follow the device to a new connection: the recorder holds the
        // old streams.
        if (s.options.reconnect_timeout.count() > 0 && !s.recorder.isValid()) {
          if (!s.reconnect()) return std::nullopt;
          continue;
        }
        throw Error("OpenNI2 device " + s.uri + " disconnected after " + frames_text(s.delivered));
      }
      throw Error("OpenNI2 device " + s.uri + " sent no frame for " + std::to_string(timeout) + " ms (after " +
                  std::to_string(s.delivered) + " frames)");
    }
    if (status != openni::STATUS_OK || ready < 0 || ready > 1) {
      throw Error("waiting for frames from " + s.uri + " failed: " + extended_error());
    }
    openni::VideoFrameRef frame;
    if (streams[ready]->readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) {
      throw Error("reading a frame from " + s.uri + " failed: " + extended_error());
    }
    if (ready == 0) {
      if (s.pending_depth) ++s.dropped;  // replaced before its colour came
      s.note_depth_index(frame.getFrameIndex());
      s.pending_depth = frame;
    } else {
      s.pending_color = frame;
    }
  }
}

std::int64_t OpenNiSource::size_hint() const { return impl_->total; }

std::string OpenNiSource::describe() const {
  const auto& k = impl_->intrinsics;
  std::string text = impl_->file ? "OpenNI2 recording " + impl_->uri + " (" + std::to_string(impl_->total) + " frames"
                                 : "OpenNI2 device " + impl_->uri + " (" + impl_->name;
  return text + ", " + std::to_string(k.width) + "x" + std::to_string(k.height) + ")";
}

bool OpenNiSource::is_file() const { return impl_->file; }
const std::string& OpenNiSource::uri() const { return impl_->uri; }
std::int64_t OpenNiSource::dropped() const { return impl_->dropped; }
std::uint64_t OpenNiSource::last_timestamp_us() const { return impl_->last_timestamp_us; }
const std::vector<DeviceReconnect>& OpenNiSource::reconnects() const { return impl_->reconnects; }

std::filesystem::path OpenNiSource::scene_folder() const {
  openni::Device& device = impl_->device->device;
  if (impl_->file || !device.isPropertySupported(kRelightDeviceSceneFolderProperty)) return {};
  std::vector<char> text(4096, '\0');
  int size = static_cast<int>(text.size());
  if (device.getProperty(kRelightDeviceSceneFolderProperty, text.data(), &size) != openni::STATUS_OK) return {};
  text.back() = '\0';
  return std::filesystem::path(text.data());
}

void OpenNiSource::start_recording(const std::filesystem::path& file) {
  Impl& s = *impl_;
  if (s.recorder.isValid()) throw LogicError("start_recording: already recording");
  // The streams are started already: Recorder::attach fails on a stream that is not.
  if (s.recorder.create(file.c_str()) != openni::STATUS_OK) {
    throw Error("cannot create recording " + file.string() + ": " + extended_error());
  }
  if (s.recorder.attach(s.depth.stream, false) != openni::STATUS_OK ||
      s.recorder.attach(s.color.stream, false) != openni::STATUS_OK || s.recorder.start() != openni::STATUS_OK) {
    const std::string detail = extended_error();
    s.recorder.destroy();
    throw Error("cannot record to " + file.string() + ": " + detail);
  }
}

void OpenNiSource::stop_recording() {
  Impl& s = *impl_;
  if (!s.recorder.isValid()) return;
  s.recorder.stop();
  s.recorder.destroy();  // closes the file
}

}  // namespace relight::capture
