// relight's OpenNI2 driver: a virtual RGB-D device (depth 1 mm uint16 + RGB888, registered, same
// camera) whose frames come from synth's scene or a TUM folder (device_uri.h, frame_producer.h).
//
// Timing: one frame thread per open device produces frame k for every size its started streams
// use, then waits until its due time (anchor + timestamp(k) - timestamp(anchor)) and hands the
// frames to the streams (new-frame callbacks run on this thread, as with real drivers). When
// producing is slower than the frame period (the synthetic renderer: ~170 ms per 640x480 frame
// on two cores, ~45 ms at 320x240) the frames come late but none is skipped and the timestamps
// stay on the device clock (k / fps apart); the anchor then moves so that a later faster phase
// never sends a burst. Pre-rendering a loop at open was rejected (seconds of blocking in
// Device::open); instead a short synthetic loop (loop=N, up to 256 MB) is cached as it is first
// rendered, so from the second pass on the device runs at its frame rate (frame_producer.cpp).
//
// Disconnect: with disconnect_after=N the thread stops after N frames of a connection and reports
// the device disconnected (the OpenNI2 core then fires OpenNI::DeviceDisconnectedListener), as an
// unplugged camera would. With reconnect_after=M the same thread then waits M frame periods and
// announces the device again (the core fires DeviceConnectedListener and makes a fresh device
// object, as for a camera plugged back in); opened again, it resumes at frame N + M, so the
// timestamps say how long the camera was away. The countdown belongs to the unplugged device
// object: closing its handle before the device is back stops it (clients keep the old handle
// until the new one opens, as OpenNiSource does). Not a timer thread of the driver's own: OpenNI2's
// shutdown holds the core's lock while it destroys the driver and announcing takes that lock, so
// joining such a thread in shutdown deadlocks when a plug-back falls due meanwhile (it did).
#include <OniCProperties.h>
#include <OniCTypes.h>
#include <Driver/OniDriverAPI.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "device_uri.h"
#include "frame_producer.h"
#include "relight/capture/relight_device.h"

namespace relight::openni_driver {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMaxDepthMm = 10000;  // what Kinect-class devices report as MAX_VALUE

template <class T>
OniStatus get_value(const T& value, void* data, int* size) {
  if (data == nullptr || size == nullptr || *size != static_cast<int>(sizeof(T))) return ONI_STATUS_BAD_PARAMETER;
  std::memcpy(data, &value, sizeof(T));
  return ONI_STATUS_OK;
}

template <class T>
OniStatus set_value(T& value, const void* data, int size) {
  if (data == nullptr || size != static_cast<int>(sizeof(T))) return ONI_STATUS_BAD_PARAMETER;
  std::memcpy(&value, data, sizeof(T));
  return ONI_STATUS_OK;
}

OniStatus get_string(const std::string& text, void* data, int* size) {
  if (data == nullptr || size == nullptr || *size <= static_cast<int>(text.size())) return ONI_STATUS_BAD_PARAMETER;
  std::memcpy(data, text.c_str(), text.size() + 1);
  *size = static_cast<int>(text.size() + 1);
  return ONI_STATUS_OK;
}

void copy_string(char (&target)[ONI_MAX_STR], const std::string& text) {
  const std::size_t n = std::min(text.size(), static_cast<std::size_t>(ONI_MAX_STR - 1));
  std::memcpy(target, text.data(), n);
  target[n] = '\0';
}

class RelightDevice;

class RelightStream final : public oni::driver::StreamBase {
 public:
  RelightStream(RelightDevice& device, OniSensorType type, OniVideoMode mode) : device_(device), type_(type), mode_(mode) {}

  OniStatus start() override;
  void stop() override;
  OniStatus getProperty(int id, void* data, int* size) override;
  OniStatus setProperty(int id, const void* data, int size) override;
  OniBool isPropertySupported(int id) override;
  void notifyAllProperties() override;

  [[nodiscard]] OniSensorType type() const { return type_; }
  [[nodiscard]] Resolution size() const {
    std::lock_guard lock(mutex_);
    return {mode_.resolutionX, mode_.resolutionY};
  }
  /// Hands one frame to the OpenNI2 core (called on the device's frame thread).
  void emit(const ProducedFrame& frame);

 private:
  [[nodiscard]] int bytes_per_pixel() const { return type_ == ONI_SENSOR_DEPTH ? 2 : 3; }

  RelightDevice& device_;
  const OniSensorType type_;
  mutable std::mutex mutex_;  // guards the properties below (set by the client, read by emit)
  OniVideoMode mode_;
  OniCropping cropping_{};
  OniBool mirroring_ = FALSE;
  OniBool auto_white_balance_ = TRUE;
  OniBool auto_exposure_ = TRUE;
};

class RelightDriver;

class RelightDevice final : public oni::driver::DeviceBase {
 public:
  /// `first_index`: the frame the device starts at (0, or where a reconnected device resumes).
  RelightDevice(RelightDriver& driver, OniDeviceInfo info, DeviceUri uri, std::unique_ptr<FrameProducer> producer,
                std::int64_t first_index)
      : driver_(driver), info_(info), uri_(std::move(uri)), producer_(std::move(producer)), first_index_(first_index) {
    for (const auto& size : producer_->resolutions()) {
      depth_modes_.push_back({ONI_PIXEL_FORMAT_DEPTH_1_MM, size.width, size.height, static_cast<int>(std::lround(uri_.fps))});
      color_modes_.push_back({ONI_PIXEL_FORMAT_RGB888, size.width, size.height, static_cast<int>(std::lround(uri_.fps))});
    }
    sensors_[0] = {ONI_SENSOR_DEPTH, static_cast<int>(depth_modes_.size()), depth_modes_.data()};
    sensors_[1] = {ONI_SENSOR_COLOR, static_cast<int>(color_modes_.size()), color_modes_.data()};
    thread_ = std::jthread([this](const std::stop_token& stop) { run(stop); });
  }

  // The frame thread goes first (the jthread is the last member but is stopped explicitly so that
  // it never sees a half-destroyed device).
  ~RelightDevice() override {
    thread_.request_stop();
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  OniStatus getSensorInfoList(OniSensorInfo** infos, int* count) override {
    *infos = sensors_;
    *count = 2;
    return ONI_STATUS_OK;
  }

  oni::driver::StreamBase* createStream(OniSensorType type) override {
    const auto& modes = type == ONI_SENSOR_DEPTH ? depth_modes_ : color_modes_;
    if (type != ONI_SENSOR_DEPTH && type != ONI_SENSOR_COLOR) return nullptr;
    std::lock_guard lock(streams_mutex_);
    streams_.push_back(std::make_unique<RelightStream>(*this, type, modes.front()));
    return streams_.back().get();
  }

  void destroyStream(oni::driver::StreamBase* stream) override {
    stream->stop();
    std::lock_guard lock(streams_mutex_);
    std::erase_if(streams_, [stream](const auto& s) { return s.get() == stream; });
  }

  OniStatus getProperty(int id, void* data, int* size) override {
    switch (id) {
      case ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION: return get_value(registration_.load(), data, size);
      case ONI_DEVICE_PROPERTY_DRIVER_VERSION: return get_value(OniVersion{0, 1, 0, 0}, data, size);
      case ONI_DEVICE_PROPERTY_HARDWARE_VERSION: return get_value(0, data, size);
      case ONI_DEVICE_PROPERTY_FIRMWARE_VERSION: return get_string("relight 0.1.0", data, size);
      case ONI_DEVICE_PROPERTY_SERIAL_NUMBER: return get_string(producer_->serial(), data, size);
      case capture::kRelightDeviceSceneFolderProperty: return get_string(producer_->scene_folder(), data, size);
      default: return ONI_STATUS_NOT_SUPPORTED;
    }
  }

  OniStatus setProperty(int id, const void* data, int size) override {
    if (id != ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION) return ONI_STATUS_NOT_SUPPORTED;
    OniImageRegistrationMode mode{};
    if (set_value(mode, data, size) != ONI_STATUS_OK || !isImageRegistrationModeSupported(mode)) {
      return ONI_STATUS_BAD_PARAMETER;
    }
    registration_ = mode;
    return ONI_STATUS_OK;
  }

  OniBool isPropertySupported(int id) override {
    return id == ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION || id == ONI_DEVICE_PROPERTY_DRIVER_VERSION ||
           id == ONI_DEVICE_PROPERTY_HARDWARE_VERSION || id == ONI_DEVICE_PROPERTY_FIRMWARE_VERSION ||
           id == ONI_DEVICE_PROPERTY_SERIAL_NUMBER || id == capture::kRelightDeviceSceneFolderProperty;
  }

  // Depth and colour come from one camera, so they are registered whichever mode is asked for.
  OniBool isImageRegistrationModeSupported(OniImageRegistrationMode mode) override {
    return mode == ONI_IMAGE_REGISTRATION_OFF || mode == ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  }

  [[nodiscard]] const FrameProducer& producer() const { return *producer_; }
  [[nodiscard]] bool supports(const OniVideoMode& mode, OniSensorType type) const {
    const auto& modes = type == ONI_SENSOR_DEPTH ? depth_modes_ : color_modes_;
    return std::any_of(modes.begin(), modes.end(), [&](const OniVideoMode& m) {
      return m.pixelFormat == mode.pixelFormat && m.resolutionX == mode.resolutionX &&
             m.resolutionY == mode.resolutionY && m.fps == mode.fps;
    });
  }

  void stream_started(RelightStream* stream) {
    {
      std::lock_guard lock(state_mutex_);
      if (std::find(started_.begin(), started_.end(), stream) == started_.end()) started_.push_back(stream);
    }
    wake_.notify_all();
  }

  // After this returns the stream gets no further frame (emission holds emit_mutex_). The mutex is
  // recursive because a client may stop a stream from inside its new-frame callback, which runs
  // on the frame thread while it emits.
  void stream_stopped(RelightStream* stream) {
    std::lock_guard emit(emit_mutex_);
    std::lock_guard lock(state_mutex_);
    std::erase(started_, stream);
  }

 private:
  void run(const std::stop_token& stop);
  /// Waits until a stream is started; `sizes` gets the resolutions the started streams want.
  bool wait_for_streams(const std::stop_token& stop, std::vector<Resolution>& sizes);

  RelightDriver& driver_;
  OniDeviceInfo info_;
  DeviceUri uri_;
  std::unique_ptr<FrameProducer> producer_;
  std::int64_t first_index_;
  std::vector<OniVideoMode> depth_modes_, color_modes_;
  OniSensorInfo sensors_[2]{};
  std::atomic<OniImageRegistrationMode> registration_{ONI_IMAGE_REGISTRATION_OFF};

  std::mutex streams_mutex_;
  std::vector<std::unique_ptr<RelightStream>> streams_;

  std::recursive_mutex emit_mutex_;
  std::mutex state_mutex_;
  std::condition_variable_any wake_;
  std::vector<RelightStream*> started_;  // guarded by state_mutex_
  std::jthread thread_;
};

class RelightDriver final : public oni::driver::DriverBase {
 public:
  explicit RelightDriver(OniDriverServices* services) : DriverBase(services) {}

  OniStatus initialize(oni::driver::DeviceConnectedCallback connected, oni::driver::DeviceDisconnectedCallback disconnected,
                       oni::driver::DeviceStateChangedCallback state_changed, void* cookie) override {
    const OniStatus status = DriverBase::initialize(connected, disconnected, state_changed, cookie);
    if (status != ONI_STATUS_OK) return status;
    // The synthetic device is always there (what `relight devices` and ANY_DEVICE find).
    announce(parse_device_uri("relight://synthetic"), "relight synthetic RGB-D (orbit)");
    return ONI_STATUS_OK;
  }

  // Any relight:// URI opens, announced or not (OpenNI2 asks tryDevice for URIs it does not know).
  OniStatus tryDevice(const char* uri) override {
    if (uri == nullptr || !is_relight_uri(uri)) return ONI_STATUS_ERROR;
    try {
      const DeviceUri parsed = parse_device_uri(uri);
      const auto producer = make_producer(parsed);
      announce(parsed, producer->name());
      return ONI_STATUS_OK;
    } catch (const std::exception& e) {
      getServices().errorLoggerAppend("%s", e.what());
      return ONI_STATUS_ERROR;
    }
  }

  oni::driver::DeviceBase* deviceOpen(const char* uri, const char* /*mode*/) override {
    try {
      DeviceUri parsed = parse_device_uri(uri == nullptr ? "" : uri);
      auto producer = make_producer(parsed);
      const OniDeviceInfo info = device_info(parsed, producer->name());
      std::lock_guard lock(mutex_);
      const auto resume = resume_index_.find(parsed.text);
      const std::int64_t first_index = resume == resume_index_.end() ? 0 : resume->second;
      devices_.push_back(
          std::make_unique<RelightDevice>(*this, info, std::move(parsed), std::move(producer), first_index));
      return devices_.back().get();
    } catch (const std::exception& e) {
      getServices().errorLoggerAppend("%s", e.what());
      return nullptr;
    }
  }

  void deviceClose(oni::driver::DeviceBase* device) override {
    std::unique_ptr<RelightDevice> closing;  // destroyed (frame thread joined) outside the lock
    std::lock_guard lock(mutex_);
    const auto it = std::find_if(devices_.begin(), devices_.end(), [device](const auto& d) { return d.get() == device; });
    if (it == devices_.end()) return;
    closing = std::move(*it);
    devices_.erase(it);
  }

  void shutdown() override {
    std::vector<std::unique_ptr<RelightDevice>> closing;
    std::lock_guard lock(mutex_);
    closing.swap(devices_);
  }

  // Our depth and colour frames of one instant are emitted together with equal timestamps and
  // frame indices, so the core's software sync pairs them; a non-null handle says "supported".
  void* enableFrameSync(oni::driver::StreamBase** /*streams*/, int /*count*/) override {
    std::lock_guard lock(mutex_);
    return sync_groups_.emplace_back(std::make_unique<int>(0)).get();
  }
  void disableFrameSync(void* group) override {
    std::lock_guard lock(mutex_);
    std::erase_if(sync_groups_, [group](const auto& g) { return g.get() == group; });
  }

  /// Called on a device's frame thread when it stops.
  void disconnected(const OniDeviceInfo& info) {
    {
      std::lock_guard lock(mutex_);
      announced_.erase(info.uri);
    }
    deviceDisconnected(&info);
  }

  /// Called on an unplugged device's frame thread when it comes back: the next open of `uri`
  /// starts at `next_index`.
  void plugged_back(const DeviceUri& uri, const std::string& name, std::int64_t next_index) {
    {
      std::lock_guard lock(mutex_);
      resume_index_[uri.text] = next_index;
    }
    announce(uri, name);
  }
  void log_error(const std::string& message) { getServices().errorLoggerAppend("%s", message.c_str()); }

 private:
  static OniDeviceInfo device_info(const DeviceUri& uri, const std::string& name) {
    OniDeviceInfo info{};
    copy_string(info.uri, uri.text);
    copy_string(info.vendor, "relight");
    copy_string(info.name, name);
    return info;
  }

  void announce(const DeviceUri& uri, const std::string& name) {
    {
      std::lock_guard lock(mutex_);
      if (!announced_.insert(uri.text).second) return;
    }
    const OniDeviceInfo info = device_info(uri, name);
    deviceConnected(&info);
  }

  std::mutex mutex_;
  std::vector<std::unique_ptr<RelightDevice>> devices_;
  std::vector<std::unique_ptr<int>> sync_groups_;
  std::set<std::string> announced_;
  std::map<std::string, std::int64_t> resume_index_;  // where a plugged-back device goes on
};

// ---- RelightStream ----

OniStatus RelightStream::start() {
  device_.stream_started(this);
  return ONI_STATUS_OK;
}

void RelightStream::stop() { device_.stream_stopped(this); }

OniStatus RelightStream::getProperty(int id, void* data, int* size) {
  std::lock_guard lock(mutex_);
  const auto [hfov, vfov] = device_.producer().field_of_view({mode_.resolutionX, mode_.resolutionY});
  switch (id) {
    case ONI_STREAM_PROPERTY_VIDEO_MODE: return get_value(mode_, data, size);
    case ONI_STREAM_PROPERTY_CROPPING: return get_value(cropping_, data, size);
    case ONI_STREAM_PROPERTY_MIRRORING: return get_value(mirroring_, data, size);
    case ONI_STREAM_PROPERTY_HORIZONTAL_FOV: return get_value(hfov, data, size);
    case ONI_STREAM_PROPERTY_VERTICAL_FOV: return get_value(vfov, data, size);
    case ONI_STREAM_PROPERTY_STRIDE: {
      const int width = cropping_.enabled ? cropping_.width : mode_.resolutionX;
      return get_value(width * bytes_per_pixel(), data, size);
    }
    case ONI_STREAM_PROPERTY_MAX_VALUE:
      return type_ == ONI_SENSOR_DEPTH ? get_value(kMaxDepthMm, data, size) : ONI_STATUS_NOT_SUPPORTED;
    case ONI_STREAM_PROPERTY_MIN_VALUE: return type_ == ONI_SENSOR_DEPTH ? get_value(0, data, size) : ONI_STATUS_NOT_SUPPORTED;
    case ONI_STREAM_PROPERTY_AUTO_WHITE_BALANCE:
      return type_ == ONI_SENSOR_COLOR ? get_value(auto_white_balance_, data, size) : ONI_STATUS_NOT_SUPPORTED;
    case ONI_STREAM_PROPERTY_AUTO_EXPOSURE:
      return type_ == ONI_SENSOR_COLOR ? get_value(auto_exposure_, data, size) : ONI_STATUS_NOT_SUPPORTED;
    default: return ONI_STATUS_NOT_SUPPORTED;
  }
}

OniStatus RelightStream::setProperty(int id, const void* data, int size) {
  std::unique_lock lock(mutex_);
  switch (id) {
    case ONI_STREAM_PROPERTY_VIDEO_MODE: {
      OniVideoMode mode{};
      if (set_value(mode, data, size) != ONI_STATUS_OK || !device_.supports(mode, type_)) return ONI_STATUS_BAD_PARAMETER;
      mode_ = mode;
      cropping_ = {};
      lock.unlock();
      raisePropertyChanged(id, &mode, sizeof(mode));
      return ONI_STATUS_OK;
    }
    case ONI_STREAM_PROPERTY_CROPPING: {
      OniCropping crop{};
      if (set_value(crop, data, size) != ONI_STATUS_OK) return ONI_STATUS_BAD_PARAMETER;
      if (crop.enabled && (crop.originX < 0 || crop.originY < 0 || crop.width <= 0 || crop.height <= 0 ||
                           crop.originX + crop.width > mode_.resolutionX || crop.originY + crop.height > mode_.resolutionY)) {
        return ONI_STATUS_BAD_PARAMETER;
      }
      cropping_ = crop;
      return ONI_STATUS_OK;
    }
    case ONI_STREAM_PROPERTY_MIRRORING: return set_value(mirroring_, data, size);
    case ONI_STREAM_PROPERTY_AUTO_WHITE_BALANCE:
      return type_ == ONI_SENSOR_COLOR ? set_value(auto_white_balance_, data, size) : ONI_STATUS_NOT_SUPPORTED;
    case ONI_STREAM_PROPERTY_AUTO_EXPOSURE:
      return type_ == ONI_SENSOR_COLOR ? set_value(auto_exposure_, data, size) : ONI_STATUS_NOT_SUPPORTED;
    default: return ONI_STATUS_NOT_SUPPORTED;
  }
}

OniBool RelightStream::isPropertySupported(int id) {
  switch (id) {
    case ONI_STREAM_PROPERTY_VIDEO_MODE:
    case ONI_STREAM_PROPERTY_CROPPING:
    case ONI_STREAM_PROPERTY_MIRRORING:
    case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
    case ONI_STREAM_PROPERTY_VERTICAL_FOV:
    case ONI_STREAM_PROPERTY_STRIDE: return TRUE;
    case ONI_STREAM_PROPERTY_MAX_VALUE:
    case ONI_STREAM_PROPERTY_MIN_VALUE: return type_ == ONI_SENSOR_DEPTH;
    case ONI_STREAM_PROPERTY_AUTO_WHITE_BALANCE:
    case ONI_STREAM_PROPERTY_AUTO_EXPOSURE: return type_ == ONI_SENSOR_COLOR;
    default: return FALSE;
  }
}

void RelightStream::notifyAllProperties() {
  OniVideoMode mode;
  {
    std::lock_guard lock(mutex_);
    mode = mode_;
  }
  raisePropertyChanged(ONI_STREAM_PROPERTY_VIDEO_MODE, &mode, sizeof(mode));
}

void RelightStream::emit(const ProducedFrame& produced) {
  OniVideoMode mode;
  OniCropping crop;
  bool mirror = false;
  {
    std::lock_guard lock(mutex_);
    mode = mode_;
    crop = cropping_;
    mirror = mirroring_ != FALSE;
  }
  if (produced.size.width != mode.resolutionX || produced.size.height != mode.resolutionY) return;  // mode just changed
  if (!crop.enabled) crop = {FALSE, 0, 0, mode.resolutionX, mode.resolutionY};
  OniFrame* frame = getServices().acquireFrame();
  if (frame == nullptr) return;
  const int bpp = bytes_per_pixel();
  const auto* source = type_ == ONI_SENSOR_DEPTH ? reinterpret_cast<const std::uint8_t*>(produced.depth.data())
                                                 : produced.rgb.data();
  auto* target = static_cast<std::uint8_t*>(frame->data);
  for (int row = 0; row < crop.height; ++row) {
    const std::uint8_t* source_row = source + static_cast<std::size_t>(crop.originY + row) * mode.resolutionX * bpp;
    std::uint8_t* target_row = target + static_cast<std::size_t>(row) * crop.width * bpp;
    if (!mirror) {
      std::memcpy(target_row, source_row + static_cast<std::size_t>(crop.originX) * bpp, static_cast<std::size_t>(crop.width) * bpp);
      continue;
    }
    // Mirroring flips the full image, cropping then cuts from the flipped image (as PS1080 does).
    for (int col = 0; col < crop.width; ++col) {
      const int source_col = mode.resolutionX - 1 - (crop.originX + col);
      std::memcpy(target_row + static_cast<std::size_t>(col) * bpp, source_row + static_cast<std::size_t>(source_col) * bpp, bpp);
    }
  }
  frame->dataSize = crop.width * crop.height * bpp;
  frame->sensorType = type_;
  frame->timestamp = produced.timestamp_us;
  frame->frameIndex = static_cast<int>(produced.index + 1);  // OpenNI frame indices start at 1
  frame->width = crop.width;
  frame->height = crop.height;
  frame->videoMode = mode;
  frame->croppingEnabled = crop.enabled;
  frame->cropOriginX = crop.originX;
  frame->cropOriginY = crop.originY;
  frame->stride = crop.width * bpp;
  raiseNewFrame(frame);
  getServices().releaseFrame(frame);
}

// ---- RelightDevice frame thread ----

bool RelightDevice::wait_for_streams(const std::stop_token& stop, std::vector<Resolution>& sizes) {
  std::unique_lock lock(state_mutex_);
  if (!wake_.wait(lock, stop, [this] { return !started_.empty(); })) return false;
  // The sizes are read while state_mutex_ is held: a client that stops and destroys a stream
  // (destroyStream) waits in stream_stopped() for it, so no stream is freed under us. Reading them
  // after the lock was released read a destroyed stream's mutex (ThreadSanitizer found it).
  sizes.clear();
  for (const RelightStream* stream : started_) {
    if (std::find(sizes.begin(), sizes.end(), stream->size()) == sizes.end()) sizes.push_back(stream->size());
  }
  return true;
}

void RelightDevice::run(const std::stop_token& stop) {
  std::int64_t index = first_index_;
  std::int64_t anchor_index = -1;  // -1: streaming (re)starts, anchor the clock at the next frame
  Clock::time_point anchor_time;
  const auto period = std::chrono::microseconds(std::llround(1e6 / uri_.fps));
  std::vector<Resolution> sizes;
  while (!stop.stop_requested()) {
    if (!wait_for_streams(stop, sizes)) return;
    std::vector<ProducedFrame> frames;
    try {
      for (const Resolution& size : sizes) frames.push_back(producer_->produce(index, size));
    } catch (const std::exception& e) {
      // A source that fails (a corrupt image in a TUM folder) is a device that stops working.
      driver_.log_error(std::string("relight device ") + info_.uri + ": " + e.what());
      driver_.disconnected(info_);
      return;
    }
    const auto now = Clock::now();
    const auto due = [&] {
      return anchor_time + std::chrono::microseconds(producer_->timestamp_us(index) - producer_->timestamp_us(anchor_index));
    };
    if (anchor_index < 0 || now > due() + period) {  // first frame, or late: re-anchor, no burst later
      anchor_index = index;
      anchor_time = now;
    }
    {
      std::unique_lock lock(state_mutex_);
      if (wake_.wait_until(lock, stop, due(), [] { return false; }); stop.stop_requested()) return;
      if (started_.empty()) {  // every stream stopped meanwhile: restart the clock next time
        anchor_index = -1;
        continue;
      }
    }
    {
      std::lock_guard emit(emit_mutex_);
      std::vector<RelightStream*> current;
      {
        std::lock_guard lock(state_mutex_);
        current = started_;
      }
      for (RelightStream* stream : current) {
        {
          std::lock_guard lock(state_mutex_);  // a callback may have stopped it
          if (std::find(started_.begin(), started_.end(), stream) == started_.end()) continue;
        }
        for (const ProducedFrame& frame : frames) {
          if (frame.size == stream->size()) stream->emit(frame);
        }
      }
    }
    ++index;
    if (uri_.disconnect_after > 0 && index - first_index_ >= uri_.disconnect_after) {
      driver_.disconnected(info_);
      if (uri_.reconnect_after > 0) {
        const auto away =
            std::chrono::microseconds(std::llround(1e6 * static_cast<double>(uri_.reconnect_after) / uri_.fps));
        std::unique_lock lock(state_mutex_);
        if (wake_.wait_for(lock, stop, away, [] { return false; }); stop.stop_requested()) return;  // closed meanwhile
        lock.unlock();
        driver_.plugged_back(uri_, info_.name, index + uri_.reconnect_after);
      }
      return;
    }
  }
}

}  // namespace

}  // namespace relight::openni_driver

// ONI_EXPORT_DRIVER allocates the driver with XN_NEW and frees it with XN_DELETE, which no
// installed OpenNI2 header defines; ownership passes to OpenNI2's oniDriverCreate/Destroy.
#define XN_NEW(type, ...) std::make_unique<type>(__VA_ARGS__).release()
#define XN_DELETE(pointer) std::unique_ptr<oni::driver::DriverBase>(pointer).reset()

ONI_EXPORT_DRIVER(relight::openni_driver::RelightDriver)
