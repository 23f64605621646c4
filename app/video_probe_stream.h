#pragma once
// Probe streams through OpenCV's VideoCapture (kept out of lights/, whose library stays free of
// video decoding): a video file of the probe camera, or a live camera (a V4L2 device).
//  - A video file is recorded: frame i has timestamp origin + i / fps, the origin being the
//    first RGB-D frame's timestamp plus `offset_s` (ProbeMatcher aligns relative streams).
//  - A camera ("/dev/videoN" or an index N) is live: each RGB-D frame takes its newest frame.
// Frames are 8-bit: decoded with the probe response (lights/probe_response.h). A camera that
// disappears or a video that ends makes the matcher keep the last good probe.
#include <memory>
#include <string>

#include "relight/lights/probe_stream.h"

namespace relight::app {

/// True for "/dev/video*" or a plain device index.
[[nodiscard]] bool is_camera_spec(const std::string& spec);

/// Opens `spec` as a camera (is_camera_spec) or a video file. Throws relight::Error naming it
/// when it cannot be opened.
[[nodiscard]] std::unique_ptr<lights::ProbeStream> open_video_probe(const std::string& spec,
                                                                    const lights::ProbeResponse& response);

/// Any probe input: a folder with probe.txt, a .txt list, a still image (lights/probe_stream.h),
/// a camera or a video file.
[[nodiscard]] std::unique_ptr<lights::ProbeStream> open_probe_input(const std::string& spec,
                                                                    const lights::ProbeResponse& response);

}  // namespace relight::app
