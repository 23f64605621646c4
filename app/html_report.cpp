#include "html_report.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "relight/lights/light_output.h"

extern char** environ;

namespace relight::app {

namespace {

using Json = nlohmann::ordered_json;

constexpr std::array<const char*, 12> kPalette = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f", "#edc948",
                                                  "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac", "#1b9e77", "#7570b3"};

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::string ms(double value) { return format(value < 10 ? "%.2f" : "%.1f", value); }

// Linear RGB in [0, 1] -> #rrggbb with the sRGB transfer curve.
std::string srgb_hex(double r, double g, double b) {
  auto encode = [](double linear) {
    linear = std::clamp(linear, 0.0, 1.0);
    const double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
    return static_cast<int>(std::lround(255 * v));
  };
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", encode(r), encode(g), encode(b));
  return text;
}

constexpr const char* kStyle = R"(
body{font:14px/1.4 system-ui,sans-serif;margin:24px;color:#222;max-width:1600px}
h1{font-size:22px;margin:0 0 12px}h2{font-size:17px;margin:28px 0 8px;border-bottom:1px solid #ddd}
table{border-collapse:collapse}td,th{padding:3px 9px;border-bottom:1px solid #eee;text-align:right}
th{background:#f4f4f4}td.l,th.l{text-align:left}.kv td:first-child{font-weight:600;text-align:left}
.sheet{display:flex;flex-wrap:wrap;gap:6px;margin-bottom:10px}.sheet figure{margin:0;font-size:12px;text-align:center}
.sheet img{display:block;border:1px solid #ccc}.sheet .frame{width:44px;font-size:12px;color:#666}
.graph svg{max-width:100%;height:auto}
.swatch{display:inline-block;width:28px;height:16px;border:1px solid #888;vertical-align:middle}
.bar{display:inline-block;height:10px;background:#4e79a7}pre{background:#f7f7f7;padding:8px;overflow:auto;font-size:12px}
.note{color:#666;font-size:12px}svg text{font:11px system-ui,sans-serif}
)";

void summary_section(std::ostringstream& html, const Json& timing) {
  html << "<table class=kv>";
  for (const char* key :
       {"sequence", "source", "compute", "frames", "seconds", "fps", "peak_rss_mb", "dropped_frames", "stopped_by"}) {
    if (!timing.contains(key)) continue;
    const Json& value = timing[key];
    std::string text = value.is_string()  ? value.get<std::string>()
                       : value.is_number_float() ? format("%.3f", value.get<double>())
                                                 : value.dump();
    html << "<tr><td>" << key << "<td class=l>" << html_escape(text);
  }
  // Summaries of one level: "key = value; ..." (lists as their length: the report.json has them).
  // An object of numbers (dir_steps' medians) shows inline; deeper ones point to report.json.
  const auto number = [](const Json& value) {
    return value.is_number_float() ? format("%.3g", value.get<double>())
           : value.is_string()     ? value.get<std::string>()
                                   : value.dump();
  };
  const auto numbers_only = [](const Json& value) {
    return std::all_of(value.begin(), value.end(), [](const Json& v) { return v.is_number(); });
  };
  const auto inline_numbers = [&](const Json& value) {
    std::string text;
    for (const auto& [inner, v] : value.items()) text += (text.empty() ? "" : ", ") + inner + " " + number(v);
    return text;
  };
  for (const char* section : {"latency_ms", "dir_steps", "tracking", "marker_pose", "camera_look", "composite"}) {
    if (!timing.contains(section) || !timing[section].is_object()) continue;
    html << "<tr><td>" << section << "<td class=l>";
    for (const auto& [key, value] : timing[section].items()) {
      const std::string text = value.is_array()      ? std::to_string(value.size()) + " entries"
                               : !value.is_object()  ? number(value)
                               : numbers_only(value) ? inline_numbers(value)
                                                     : "(see report.json)";
      html << html_escape(key) << " = " << html_escape(text) << "; ";
    }
  }
  html << "</table>\n";
}

// One line per frame; pictures keep their aspect ratio at one height and wrap on narrow windows.
void contact_sheet_section(std::ostringstream& html, const ReportContent& content) {
  html << "<h2>Contact sheet</h2>\n";
  bool any = false;
  for (const auto& row : content.contact_sheet) {
    if (row.pictures.empty()) continue;
    any = true;
    html << "<div class=sheet><div class=frame>frame<br>" << row.frame << "</div>";
    for (const auto& picture : row.pictures) {
      html << "<figure><img alt=\"" << html_escape(picture.buffer) << " frame " << row.frame << "\" width="
           << picture.width << " height=" << picture.height << " src=\"data:image/jpeg;base64," << base64(picture.jpeg)
           << "\"><figcaption>" << html_escape(picture.buffer) << "</figcaption></figure>";
    }
    html << "</div>\n";
  }
  if (!any) html << "<p class=note>No pictures were collected.</p>\n";
}

// The composite as rendered beside the composite with the camera's look, at full resolution.
void camera_look_section(std::ostringstream& html, const CloseUp& close_up) {
  html << "<h2>Camera look (frame " << close_up.frame
       << ")</h2>\n<p class=note>The virtual objects as rendered, "
          "and with the camera's blur, motion blur and noise measured in this frame (camera_look), 2x, "
          "nearest pixel.</p>\n<div class=sheet>";
  for (const Thumbnail* picture : {&close_up.before, &close_up.after}) {
    html << "<figure><img alt=\"" << html_escape(picture->buffer) << "\" width=" << picture->width
         << " height=" << picture->height << " style=\"image-rendering:pixelated\" src=\"data:image/png;base64,"
         << base64(picture->jpeg) << "\"><figcaption>" << html_escape(picture->buffer) << "</figcaption></figure>";
  }
  html << "</div>\n";
}

void timing_table(std::ostringstream& html, const Json& stages) {
  double total = 0;
  for (const auto& stage : stages) total += stage.value("median_ms", 0.0);
  html << "<table><tr><th class=l>stage<th class=l>backend<th class=l>buffers<th>frames<th>median "
          "ms<th>mean<th>p95<th>max"
          "<th>device ms<th title=\"CPU time of the process during the stage over its wall time\">cores busy"
          "<th class=l>share of the median frame\n";
  for (const auto& stage : stages) {
    const double median = stage.value("median_ms", 0.0);
    const double share = total > 0 ? median / total : 0;
    html << "<tr><td class=l>" << html_escape(stage.value("stage", "")) << "<td class=l>"
         << html_escape(stage.value("backend", "")) << "<td class=l>" << html_escape(stage.value("buffers", ""))
         << "<td>" << stage.value("frames", 0) << "<td>" << ms(median) << "<td>" << ms(stage.value("mean_ms", 0.0))
         << "<td>" << ms(stage.value("p95_ms", 0.0)) << "<td>" << ms(stage.value("max_ms", 0.0)) << "<td>"
         << (stage.contains("device_median_ms") ? ms(stage["device_median_ms"].get<double>()) : "") << "<td>"
         << (stage.contains("cpu_median_ms") && median > 0
                 ? format("%.1f", stage["cpu_median_ms"].get<double>() / median)
                 : "")
         << "<td class=l>"
         << "<span class=bar style=\"width:" << std::lround(200 * share) << "px\"></span> "
         << format("%.0f %%", 100 * share) << "\n";
  }
  html << "<tr><th class=l>sum of medians<th><th><th><th>" << ms(total) << "<th colspan=6></table>\n";
}

// Stacked areas: each stage's wall time per frame on top of the stages before it.
void timing_plot(std::ostringstream& html, const Json& stages) {
  std::vector<std::vector<double>> series;
  std::size_t frames = 0;
  for (const auto& stage : stages) {
    series.push_back(stage.value("wall_ms", std::vector<double>{}));
    frames = std::max(frames, series.back().size());
  }
  if (frames < 2) return;
  std::vector<double> totals(frames, 0.0);
  for (const auto& values : series) {
    for (std::size_t i = 0; i < values.size(); ++i) totals[i] += values[i];
  }
  // The first frame carries one-time set-up (pipelines, allocations): scale to the others.
  const double top = std::max(1e-3, *std::max_element(totals.begin() + 1, totals.end()) * 1.05);
  const bool clipped = totals[0] > top;
  const double width = 760, height = 280, left = 48, bottom = 24, right = 170;
  auto x = [&](std::size_t i) { return left + (width - left - right) * static_cast<double>(i) / static_cast<double>(frames - 1); };
  auto y = [&](double value) { return height - bottom - (height - bottom - 8) * std::min(value, top) / top; };
  html << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=" << width << " height=" << height << " viewBox=\"0 0 "
       << width << " " << height << "\" role=img aria-label=\"stage timings per frame\">\n";
  for (int tick = 0; tick <= 4; ++tick) {
    const double value = top * tick / 4;
    html << "<line x1=" << left << " x2=" << x(frames - 1) << " y1=" << y(value) << " y2=" << y(value)
         << " stroke=\"#e5e5e5\"/><text x=" << left - 4 << " y=" << y(value) + 4 << " text-anchor=end>" << ms(value)
         << "</text>\n";
  }
  std::vector<double> below(frames, 0.0);
  for (std::size_t s = 0; s < series.size(); ++s) {
    std::ostringstream points;
    std::vector<double> above = below;
    for (std::size_t i = 0; i < series[s].size(); ++i) above[i] += series[s][i];
    for (std::size_t i = 0; i < frames; ++i) points << x(i) << "," << y(above[i]) << " ";
    for (std::size_t i = frames; i-- > 0;) points << x(i) << "," << y(below[i]) << " ";
    const char* colour = kPalette[s % kPalette.size()];
    html << "<polygon fill=\"" << colour << "\" fill-opacity=0.85 points=\"" << points.str() << "\"/>\n";
    html << "<rect x=" << width - right + 12 << " y=" << 10 + 15 * s << " width=10 height=10 fill=\"" << colour
         << "\"/><text x=" << width - right + 26 << " y=" << 19 + 15 * s << ">"
         << html_escape(stages[s].value("stage", "")) << "</text>\n";
    below = std::move(above);
  }
  html << "<text x=" << left << " y=" << height - 6 << ">frame 0</text><text x=" << x(frames - 1) << " y="
       << height - 6 << " text-anchor=end>frame " << frames - 1 << "</text>\n</svg>\n";
  html << "<p class=note>Wall time per stage and frame, stacked (ms)."
       << (clipped ? " Frame 0 (" + ms(totals[0]) + " ms, including one-time set-up) is clipped." : std::string())
       << "</p>\n";
}

void materials_section(std::ostringstream& html, const std::vector<brdf::MaterialParams>& materials) {
  html << "<h2>Estimated materials (last frame)</h2>\n<table><tr><th>cluster<th class=l>k<sub>d</sub><th>r<th>g<th>b"
          "<th>k<sub>s</sub><th>n<th>pixels<th>fit RMS\n";
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const auto& m = materials[i];
    html << "<tr><td>" << i + 1 << "<td class=l><span class=swatch style=\"background:"
         << srgb_hex(m.kd.x(), m.kd.y(), m.kd.z()) << "\"></span><td>" << format("%.3f", m.kd.x()) << "<td>"
         << format("%.3f", m.kd.y()) << "<td>" << format("%.3f", m.kd.z()) << "<td>" << format("%.3f", m.ks) << "<td>"
         << format("%.1f", m.n) << "<td>" << m.pixels << "<td>"
         << (m.fit_rms < 0 ? std::string("not fitted") : format("%.4f", m.fit_rms)) << "\n";
  }
  html << "</table>\n";
}

// Directional lights on a sky dome seen from above: the centre is the zenith, the circle the horizon.
void light_dome(std::ostringstream& html, const lights::LightSet& set) {
  double brightest = 0;
  for (const auto& light : set.lights) brightest = std::max(brightest, lights::luminance(light.power));
  const double radius = 110, centre = 130;
  html << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=260 height=260 viewBox=\"0 0 260 260\" role=img "
          "aria-label=\"light directions\"><circle cx="
       << centre << " cy=" << centre << " r=" << radius << " fill=\"#20283a\"/><circle cx=" << centre << " cy=" << centre
       << " r=" << radius / 2 << " fill=none stroke=\"#556\"/>\n";
  for (const auto& light : set.lights) {
    if (light.kind != lights::LightKind::Directional) continue;
    const auto d = light.direction.normalized();
    const double elevation = std::asin(std::clamp(d.z(), -1.0, 1.0));
    const double r = std::min(1.1, 1 - elevation / (M_PI / 2)) * radius;
    const double azimuth = std::atan2(d.y(), d.x());
    const double size = 3 + 9 * (brightest > 0 ? std::sqrt(lights::luminance(light.power) / brightest) : 0);
    const double peak = std::max({light.power.x(), light.power.y(), light.power.z(), 1e-12});
    html << "<circle cx=" << centre + r * std::cos(azimuth) << " cy=" << centre - r * std::sin(azimuth)
         << " r=" << size << " fill=\"" << srgb_hex(light.power.x() / peak, light.power.y() / peak, light.power.z() / peak)
         << "\" stroke=\"" << (light.real ? "#fff" : "#f0f") << "\"/>\n";
  }
  html << "<text x=" << centre << " y=14 text-anchor=middle>+y</text><text x=" << centre + radius + 4 << " y="
       << centre + 4 << ">+x</text></svg>\n";
}

void lights_section(std::ostringstream& html, const lights::LightSet& set) {
  html << "<h2>Lights (last frame)</h2>\n<div style=\"display:flex;gap:24px;align-items:flex-start\">";
  light_dome(html, set);
  html << "<table><tr><th>#<th class=l>kind<th class=l>direction / position<th class=l>power (RGB)<th class=l>real\n";
  for (std::size_t i = 0; i < set.lights.size(); ++i) {
    const auto& light = set.lights[i];
    const auto& where = light.kind == lights::LightKind::Directional ? light.direction : light.position;
    html << "<tr><td>" << i + 1 << "<td class=l>" << lights::light_kind_name(light.kind) << "<td class=l>"
         << format("%.3f", where.x()) << ", " << format("%.3f", where.y()) << ", " << format("%.3f", where.z())
         << "<td class=l>" << format("%.4g", light.power.x()) << ", " << format("%.4g", light.power.y()) << ", "
         << format("%.4g", light.power.z()) << "<td class=l>" << (light.real ? "real" : "virtual") << "\n";
  }
  html << "</table></div>\n<p class=note>Directions in the world frame (z up); the dome shows directional lights seen "
          "from above, the zenith in the centre, the horizon on the circle; white rims are real lights.</p>\n";
}

void graph_section(std::ostringstream& html, const Json& timing, const std::string& dot,
                   const std::optional<std::string>& svg) {
  html << "<h2>Frame graph</h2>\n";
  if (svg) {
    html << "<div class=graph>" << *svg << "</div>\n";
    return;
  }
  html << "<p class=note>Graphviz (dot) is not installed, so the graph is listed. Execution order:</p><ol>";
  for (const auto& stage : timing.value("execution_order", Json::array())) {
    html << "<li>" << html_escape(stage.get<std::string>());
  }
  html << "</ol>\n<pre>" << html_escape(dot) << "</pre>\n";
}

std::filesystem::path unique_temp(const char* suffix) {
  static int counter = 0;
  return std::filesystem::temp_directory_path() /
         ("relight-report-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + suffix);
}

}  // namespace

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t group = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      group = (group << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    }
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(group >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string html_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string html_report(const std::string& title, const nlohmann::ordered_json& timing, const ReportContent& content,
                        const std::string& graph_dot, const std::optional<std::string>& graph_svg) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>" << html_escape(title)
       << "</title><style>" << kStyle << "</style></head><body>\n<h1>" << html_escape(title) << "</h1>\n";
  summary_section(html, timing);
  contact_sheet_section(html, content);
  if (content.camera_look) camera_look_section(html, *content.camera_look);
  const Json stages = timing.value("stages", Json::array());
  html << "<h2>Stage timings</h2>\n";
  timing_table(html, stages);
  timing_plot(html, stages);
  if (content.materials) materials_section(html, *content.materials);
  if (content.lights) lights_section(html, *content.lights);
  graph_section(html, timing, graph_dot, graph_svg);
  html << "</body></html>\n";
  return html.str();
}

std::optional<std::string> render_dot_svg(const std::string& dot) {
  const auto input = unique_temp(".dot");
  const auto output = unique_temp(".svg");
  {
    std::ofstream file(input, std::ios::binary);
    file << dot;
    if (!file) return std::nullopt;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  const std::string in = input.string(), out = output.string();
  std::array<const char*, 6> argv = {"dot", "-Tsvg", "-o", out.c_str(), in.c_str(), nullptr};
  pid_t child = 0;
  const int spawned = posix_spawnp(&child, "dot", &actions, nullptr, const_cast<char* const*>(argv.data()), environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  const bool ok = spawned == 0 && ::waitpid(child, &status, 0) == child && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  std::optional<std::string> svg;
  if (ok) {
    std::ifstream file(output, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (const auto start = text.find("<svg"); start != std::string::npos) svg = text.substr(start);
  }
  std::error_code ignored;
  std::filesystem::remove(input, ignored);
  std::filesystem::remove(output, ignored);
  return svg;
}

}  // namespace relight::app
