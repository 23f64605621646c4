#pragma once
// report.html: one self-contained page (no network resources; pictures inlined as data URIs,
// plots as inline SVG) that shows what a run did: a contact sheet of the stages' pictures for a
// few frames, the per-stage timing table and a plot of the timings over frames, the estimated
// materials and lights, and the frame graph (drawn by Graphviz when `dot` is installed, otherwise
// the execution order and the DOT text).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "relight/brdf/materials.h"
#include "relight/lights/light_set.h"

namespace relight::app {

struct Thumbnail {
  std::string buffer;
  std::string jpeg;  ///< encoded bytes (JPEG; a CloseUp's are PNG)
  int width = 0, height = 0;
};

struct ContactSheetRow {
  std::int64_t frame = -1;  ///< -1: no picture was taken for this row
  std::vector<Thumbnail> pictures;
};

/// The same crop around the virtual objects in two pictures, at full resolution (scaled up).
struct CloseUp {
  std::int64_t frame = -1;
  Thumbnail before, after;
};

struct ReportContent {
  std::vector<ContactSheetRow> contact_sheet;
  std::optional<CloseUp> camera_look;                          ///< the composite as rendered and with the camera's look
  std::optional<std::vector<brdf::MaterialParams>> materials;  ///< of the last frame
  std::optional<lights::LightSet> lights;                      ///< of the last frame
};

/// The whole page. `timing` is timing_report()'s object with the run's extra keys (sequence,
/// compute, ...); `graph_svg` is Graphviz's drawing of `graph_dot`, when there is one.
[[nodiscard]] std::string html_report(const std::string& title, const nlohmann::ordered_json& timing,
                                      const ReportContent& content, const std::string& graph_dot,
                                      const std::optional<std::string>& graph_svg);

/// Graphviz's SVG of a DOT graph, or nothing when `dot` is not on PATH or fails.
[[nodiscard]] std::optional<std::string> render_dot_svg(const std::string& dot);

/// RFC 4648 base64, for data URIs.
[[nodiscard]] std::string base64(const std::string& bytes);
/// Text with &, <, >, " escaped for HTML.
[[nodiscard]] std::string html_escape(const std::string& text);

}  // namespace relight::app
