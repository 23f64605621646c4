#pragma once
// Device URIs of relight's OpenNI2 driver:
//   relight://synthetic[?key=value&...]   frames of synth::default_indoor_scene() along a synth
//                                          trajectory, rendered on the fly (see frame_producer.h)
//   relight://tum/<folder>[?key=value&...] a TUM RGB-D folder, looping; <folder> absolute
//                                          (relight://tum//data/seq) or relative to the working
//                                          directory
// Keys (all optional):
//   fps=30                 frame rate and timestamp spacing (synthetic; TUM uses its timestamps)
//   disconnect_after=N     after N frames the device reports itself disconnected (an unplugged
//                          camera, for testing clients); 0 = never. Counted per connection: a
//                          device opened again (or plugged back) disconnects after N more
//   reconnect_after=M      with disconnect_after: M frame periods (M / fps seconds) after the
//                          disconnect the device is plugged back (announced again; opening it
//                          fails until then) and, opened again, goes on at frame N + M with
//                          its timestamps, as a camera that was away while the scene went on;
//                          0 = it stays away until opened again (the default)
//   seed=0                 synth seed (handheld trajectory, noise)
//   trajectory=orbit       static | orbit | handheld
//   loop=540               synthetic trajectory length before it repeats (540 frames = one orbit);
//                          a loop that fits in 256 MB (<= 213 frames at 640x480, 853 at
//                          320x240) is rendered once and then served from memory at full rate
//   noise=none             none | kinect1 (synth's Kinect v1 depth noise)
//   size=640x480           default video mode of both streams (synthetic: 640x480 or 320x240)
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace relight::openni_driver {

struct DeviceUri {
  enum class Kind { Synthetic, Tum };
  Kind kind = Kind::Synthetic;
  std::string text;              ///< the URI as given
  std::filesystem::path folder;  ///< Tum
  double fps = 30.0;
  std::int64_t disconnect_after = 0;
  std::int64_t reconnect_after = 0;
  std::uint64_t seed = 0;
  std::string trajectory = "orbit";
  int loop = 540;
  bool noise = false;
  int width = 0;  ///< 0 = the source's native size (640x480 synthetic, the TUM images' size)
  int height = 0;
};

/// True when the URI belongs to this driver (starts with "relight://").
[[nodiscard]] bool is_relight_uri(std::string_view uri);
/// Parses a relight:// URI; throws relight::Error naming the bad part.
[[nodiscard]] DeviceUri parse_device_uri(std::string_view uri);

}  // namespace relight::openni_driver
