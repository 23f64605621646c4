#pragma once
// Frames from OpenNI2 (Debian's 2.2): a live device (Kinect-class camera, or relight's own virtual
// device relight://synthetic / relight://tum/<folder>, see openni_driver/) or a recorded
// .oni file played back through OpenNI2's file device. OpenNI.h stays out of this header.
//
// Reading follows docs/platform.md: every wait is OpenNI::waitForAnyStream with a
// timeout (a plain readFrame blocks forever on an unplugged device), a device-disconnected
// listener turns an unplug into a relight::Error (or, with a reconnect timeout, into a wait for the
// device to be plugged back, after which reading goes on), and .oni files are read sequentially
// (seek crashes in this OpenNI2 version), their end being the wait timing out.
//
// Depth (1 mm) and colour are opened at their default video modes, with depth-to-colour
// registration and frame sync where the device supports them; depth and colour are paired by
// timestamp (within half a frame period), unpaired or skipped frames count as dropped.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "relight/capture/frame_source.h"

namespace relight::capture {

struct OpenNiOptions {
  /// Device URI (as `relight devices` lists), a .oni file, or empty for the first device found.
  std::string uri;
  /// Longest wait for a frame before a live device counts as stalled (an error; generous because
  /// relight's synthetic device renders a 640x480 frame in up to ~1 s on two busy cores). A .oni
  /// file, whose frames are there at once, ends when none comes within min(timeout, 2 s).
  std::chrono::milliseconds timeout{10000};
  /// Intrinsics of the registered images; default: from the depth stream's field of view with the
  /// principal point at the image centre.
  std::optional<PinholeIntrinsics> intrinsics;
  /// How long next() waits for a live device that was unplugged to come back: it opens the same
  /// URI again (the first device, when `uri` is empty) every 100 ms and goes on with the new
  /// connection's frames. 0: an unplug is an error at once. Not while recording to a .oni file.
  std::chrono::milliseconds reconnect_timeout{0};
  /// Asked while waiting for the device to come back: true gives up and ends the stream (next()
  /// returns nullopt), e.g. on Ctrl-C.
  std::function<bool()> stop_waiting;
  /// Told, one line each, when the device is gone and being waited for and when it is back.
  std::function<void(const std::string&)> on_notice;
};

/// One unplug that the device came back from.
struct DeviceReconnect {
  std::int64_t after_frames = 0;  ///< frames next() had returned when the device went away
  double seconds_away = 0.0;      ///< from the last frame before the unplug to the first after it
};

struct OpenNiDeviceInfo {
  std::string uri;
  std::string vendor;
  std::string name;
};

/// The devices OpenNI2 sees (relight's virtual device among them). Throws if OpenNI2 fails to start.
[[nodiscard]] std::vector<OpenNiDeviceInfo> list_openni_devices();

/// What a recording holds, read back from the file after it was closed.
struct OniRecordingSummary {
  std::int64_t depth_frames = 0;
  std::int64_t color_frames = 0;
  /// Depth timestamps in file order, microseconds; OpenNI2 plays them back relative to the first.
  std::vector<std::uint64_t> depth_timestamps_us;
};

/// Frames in a .oni file per stream and the depth timestamps (read sequentially through OpenNI2's
/// file device). Throws on a bad file.
[[nodiscard]] OniRecordingSummary inspect_oni(const std::filesystem::path& file);

class OpenNiSource final : public FrameSource {
 public:
  /// Opens the device or file and starts depth and colour. Throws relight::Error with a clear
  /// message (no such device, truncated .oni, no depth stream, ...).
  explicit OpenNiSource(OpenNiOptions options);
  ~OpenNiSource() override;
  OpenNiSource(const OpenNiSource&) = delete;
  OpenNiSource& operator=(const OpenNiSource&) = delete;

  /// The next registered depth + colour pair; nullopt at the end of a .oni file. Throws
  /// relight::Error when a live device disconnects or stalls.
  [[nodiscard]] std::optional<RgbdFrame> next() override;
  /// Frames in a .oni file; 0 for live devices.
  [[nodiscard]] std::int64_t size_hint() const override;
  [[nodiscard]] std::string describe() const override;

  [[nodiscard]] bool is_file() const;
  [[nodiscard]] const std::string& uri() const;
  /// Frames the device sent that next() did not return (skipped frame indices, unpaired frames).
  [[nodiscard]] std::int64_t dropped() const;
  /// Device timestamp of the last frame next() returned, microseconds (as OpenNI2 reports it).
  [[nodiscard]] std::uint64_t last_timestamp_us() const;
  /// The unplugs the device came back from (see OpenNiOptions::reconnect_timeout).
  [[nodiscard]] const std::vector<DeviceReconnect>& reconnects() const;
  /// The folder with the device scene's scene.json and probe.hdr that relight's own driver
  /// serves (relight_device.h); empty for any other device.
  [[nodiscard]] std::filesystem::path scene_folder() const;

  /// Records both streams into a .oni file with openni::Recorder (lossless) until stop_recording().
  void start_recording(const std::filesystem::path& file);
  void stop_recording();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relight::capture
