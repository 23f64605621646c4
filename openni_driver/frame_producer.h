#pragma once
// Where the virtual device's frames come from. produce() is called on the device's frame thread
// and may be slow (the synthetic renderer takes ~170 ms for 640x480 on two cores); the device
// paces delivery by the frames' timestamps, never faster than real time (see driver.cpp).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "device_uri.h"

namespace relight::openni_driver {

struct Resolution {
  int width = 0;
  int height = 0;
  friend bool operator==(const Resolution&, const Resolution&) = default;
};

/// One registered depth + colour frame (same camera, same instant).
struct ProducedFrame {
  std::int64_t index = 0;            ///< 0-based position in the stream (OpenNI frameIndex = index + 1)
  std::uint64_t timestamp_us = 0;    ///< device clock, microseconds
  Resolution size;
  std::vector<std::uint16_t> depth;  ///< millimetres, row-major, 0 = no measurement
  std::vector<std::uint8_t> rgb;     ///< RGB888, row-major
};

class FrameProducer {
 public:
  virtual ~FrameProducer() = default;
  /// The sizes the device offers (both streams); the first is the default video mode.
  [[nodiscard]] virtual std::vector<Resolution> resolutions() const = 0;
  /// Frame `index` (0, 1, 2, ... forever; sources loop) at one of resolutions().
  [[nodiscard]] virtual ProducedFrame produce(std::int64_t index, Resolution size) const = 0;
  [[nodiscard]] virtual std::uint64_t timestamp_us(std::int64_t index) const = 0;
  /// Field of view in radians at a given size: {horizontal, vertical}.
  [[nodiscard]] virtual std::pair<float, float> field_of_view(Resolution size) const = 0;
  [[nodiscard]] virtual std::string name() const = 0;    ///< OniDeviceInfo::name
  [[nodiscard]] virtual std::string serial() const = 0;  ///< ONI_DEVICE_PROPERTY_SERIAL_NUMBER
  /// kRelightDeviceSceneFolderProperty (relight/capture/relight_device.h): a folder with the
  /// scene's scene.json and probe.hdr, "" when there is none. Any thread may call it.
  [[nodiscard]] virtual std::string scene_folder() const = 0;
};

/// The producer a URI names. Throws relight::Error (missing TUM folder, unsupported size, ...).
[[nodiscard]] std::unique_ptr<FrameProducer> make_producer(const DeviceUri& uri);

}  // namespace relight::openni_driver
