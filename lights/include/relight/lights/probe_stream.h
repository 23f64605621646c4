#pragma once
// The light probe as a stream beside the RGB-D source (Knecht 2010 §6, dissertation §4.2: a
// fisheye camera films the real light every frame), and the matching of its frames to RGB-D frames.
//
// Sources (open_probe_stream; a video file or a camera: app/video_probe_stream.h):
//  - a probe list: `probe.txt`, TUM style, one "timestamp filename" per line ('#' comments),
//    file names relative to the list, timestamps strictly increasing; or a folder holding one;
//  - one still image (an HDR probe of a static scene): the same probe for every frame.
// Images: Radiance .hdr or OpenEXR .exr (linear radiance), or 8-bit PNG/JPEG turned into
// radiance with a response curve and exposure (probe_response.h).
//
// ProbeMatcher gives each RGB-D frame the probe frame nearest to its timestamp when it is
// within `tolerance_s`; otherwise, or when the stream has ended, cannot be read, or delivers a
// black or mostly clipped frame, it keeps the last good probe (so the lights stay what they were)
// and warns once per kind of trouble. Only the very first probe must be good.
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/lights/probe_response.h"

namespace relight::lights {

struct ProbeFrame {
  Timestamp timestamp = 0.0;
  std::string name;  ///< the file, or the frame of a video, for messages
  RadianceImage radiance;
  double clipped_share = 0.0;  ///< 8-bit probes: share of expanded (saturated) pixels
};

/// How RGB-D frames find their probe frame.
enum class ProbeTiming {
  Timestamped,  ///< recorded: the frame nearest in time
  Latest,       ///< a live camera: the newest frame it has
  Still,        ///< one image for every frame
};

/// A source of probe frames with a position: the frame it was last advanced to.
class ProbeStream {
 public:
  virtual ~ProbeStream() = default;
  /// Timestamp of the frame after the current one (seconds, the RGB-D source's clock); nullopt
  /// at the end. Does not move.
  [[nodiscard]] virtual std::optional<Timestamp> next_timestamp() = 0;
  /// Moves to the next frame without decoding it (there must be one).
  virtual void advance() = 0;
  /// Decodes the current frame; throws relight::Error when it cannot be read.
  [[nodiscard]] virtual ProbeFrame decode() = 0;
  /// Back to before the first frame (a looped replay); false where the source cannot.
  virtual bool rewind() = 0;
  [[nodiscard]] virtual ProbeTiming timing() const = 0;
  /// True when timestamps count from the stream's start (a video file): the matcher puts that
  /// start at the first RGB-D frame's timestamp plus ProbeMatchOptions::offset_s.
  [[nodiscard]] virtual bool relative_timestamps() const { return false; }
  [[nodiscard]] virtual std::string describe() const = 0;
};

/// Reads one probe image: .hdr/.exr as radiance, .png/.jpg/.jpeg through `response`.
[[nodiscard]] ProbeFrame read_probe_image(const std::filesystem::path& path, const ProbeResponse& response);

/// A probe list (see above). Throws relight::Error naming the list and line: unreadable, empty,
/// malformed, timestamps not increasing, or a listed file that does not exist.
[[nodiscard]] std::unique_ptr<ProbeStream> open_probe_list(const std::filesystem::path& list,
                                                           const ProbeResponse& response);
/// One still image; read once, when the matcher first asks.
[[nodiscard]] std::unique_ptr<ProbeStream> open_still_probe(const std::filesystem::path& image,
                                                            const ProbeResponse& response);
/// A folder with probe.txt, a .txt list, or a still image (by extension); nullptr for any other
/// path (which a caller may open as a video). Throws relight::Error as the openers above.
[[nodiscard]] std::unique_ptr<ProbeStream> open_probe_stream(const std::filesystem::path& path,
                                                             const ProbeResponse& response);

struct ProbeMatchOptions {
  double tolerance_s = 0.05;      ///< farthest a matched probe frame may be from the RGB-D frame
  double offset_s = 0.0;          ///< relative streams: probe time 0 is the first RGB-D frame's time + this
  double clipped_warning = 0.02;  ///< warn (once) when a frame has more than this share clipped
  double clipped_unusable = 0.5;  ///< a frame with more clipped than this is not used
};

class ProbeMatcher {
 public:
  /// `warnings` receives the once-per-kind "relight: warning: ..." lines.
  ProbeMatcher(std::unique_ptr<ProbeStream> stream, ProbeMatchOptions options, std::ostream& warnings);
  ~ProbeMatcher();
  ProbeMatcher(ProbeMatcher&&) noexcept;

  /// The probe for the RGB-D frame at `timestamp`. Throws relight::Error when no good probe has
  /// been seen yet (the first one is missing, unreadable, black or clipped).
  const RadianceImage& probe_for(Timestamp timestamp);

  /// For report.json: the source, frames decoded and used, frames that kept the last probe
  /// (with why), the largest clipped share.
  [[nodiscard]] nlohmann::ordered_json summary() const;
  [[nodiscard]] const ProbeStream& stream() const { return *stream_; }
  [[nodiscard]] int frames_kept() const { return kept_; }  ///< RGB-D frames that reused the last probe
  [[nodiscard]] int probes_used() const { return used_; }  ///< good probe frames taken

 private:
  void match_timestamped(Timestamp timestamp);
  void take_current_frame();
  void consider(ProbeFrame frame);
  void keep_last(const std::string& kind, const std::string& trouble);

  std::unique_ptr<ProbeStream> stream_;
  ProbeMatchOptions options_;
  std::ostream* warnings_;
  std::optional<ProbeFrame> current_;
  std::optional<Timestamp> position_;  // timestamp of the stream's current frame
  bool position_decoded_ = false;      // the current frame was decoded (taken or rejected)
  std::optional<Timestamp> last_request_;
  std::optional<Timestamp> origin_;  // relative streams: the RGB-D time of probe time 0
  std::set<std::string> warned_;
  std::vector<std::string> kept_reasons_;
  int used_ = 0;
  int kept_ = 0;
  double max_clipped_ = 0.0;
};

}  // namespace relight::lights
