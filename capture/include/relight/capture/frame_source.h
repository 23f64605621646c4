#pragma once
// Live capture and replay behind one interface (as ElasticFusion's CameraInterface), so that the
// frame graph, the CLI and the tests do not care where frames come from.
#include <cstdint>
#include <optional>
#include <string>

#include "relight/core/rgbd_frame.h"

namespace relight::capture {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame, or nullopt at the end of the stream. Throws relight::Error on bad data.
  [[nodiscard]] virtual std::optional<RgbdFrame> next() = 0;
  /// Number of frames when known in advance (replay), 0 for live sources.
  [[nodiscard]] virtual std::int64_t size_hint() const = 0;
  /// One line for logs and reports, e.g. "TUM folder data/tum_fr1_rpy (4 frames, fr1 intrinsics)".
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace relight::capture
