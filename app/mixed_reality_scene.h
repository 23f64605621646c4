#pragma once
// What the commands that render virtual objects into a sequence share (render-reference,
// replay, live): telling a synthetic sequence from a recorded one, the real lights of each, and
// the virtual objects and lights given on the command line.
#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "relight/core/error.h"
#include "relight/lights/light_set.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/scene/virtual_model.h"

namespace relight::app {

/// Where a virtual object goes when --place is not given on a synthetic sequence: on the table,
/// to the right of the marker.
inline constexpr const char* kDefaultSynthPlacement = "0.35,-0.2,0.75,30";

/// True for a sequence written by `relight synth` (its scene.json says so).
[[nodiscard]] bool is_synthetic(const std::filesystem::path& sequence);

/// "x,y,z,intensity[,r,g,b]": a virtual point light of radiant intensity intensity * (r,g,b) W/sr.
[[nodiscard]] render::MrLight parse_virtual_light(const std::string& text);

/// intensity x (r, g, b) from v[first] and, when present, v[first + 1 .. first + 3] (the
/// "intensity[,r,g,b]" tail of a light option's numbers). Throws relight::Error naming `option`
/// and `text` when either is negative.
template <class T>
[[nodiscard]] Eigen::Matrix<T, 3, 1> parse_intensity(const char* option, const std::string& text,
                                                     const std::vector<T>& v, std::size_t first) {
  using Vec = Eigen::Matrix<T, 3, 1>;
  const Vec colour = v.size() == first + 4 ? Vec(v[first + 1], v[first + 2], v[first + 3]) : Vec::Ones();
  if (v[first] < T(0) || colour.minCoeff() < T(0))
    throw Error(std::string(option) + " '" + text + "': intensity and colour must not be negative");
  return v[first] * colour;
}

/// A spot's light fades out between this fraction of its angle and the whole angle.
inline constexpr float kSpotInnerFraction = 0.8f;
/// "x,y,z,target_x,target_y,target_z,angle_degrees,intensity[,r,g,b]": a spot light at (x, y, z)
/// aimed at the target, its cone's half-angle in (0, 90) degrees (full intensity within
/// kSpotInnerFraction of it), intensity * (r,g,b) W/sr on its axis. `option` names it in errors
/// (--virtual-spot, --real-spot); `real`: a lamp of the real scene (it lights both worlds of
/// differential rendering and its RSMs are split by layer, reflective_shadow_map.h).
[[nodiscard]] render::MrLight parse_spot(const std::string& option, const std::string& text, bool real);
[[nodiscard]] inline render::MrLight parse_virtual_spot(const std::string& text) {
  return parse_spot("--virtual-spot", text, false);
}

/// The model in `file` (render::load_model), its warnings printed to stderr one line each.
[[nodiscard]] render::VirtualModel load_model_telling_warnings(const std::filesystem::path& file);

/// Throws relight::Error unless there is one --real-place for each --real-object.
void check_real_places(const std::vector<std::filesystem::path>& objects, const std::vector<std::string>& places);
/// The real objects of --real-object and --real-place (render::add_real_model), loaded.
[[nodiscard]] std::vector<std::pair<render::VirtualModel, render::Placement>> load_real_objects(
    const std::vector<std::filesystem::path>& objects, const std::vector<std::string>& places);
/// What report.json and ref.json say of them: [{"model": file name, "place": its placement}].
[[nodiscard]] nlohmann::ordered_json real_objects_json(const std::vector<std::filesystem::path>& objects,
                                                       const std::vector<std::string>& places);

/// The measured lights of a recorded sequence: the lights JSON of `relight lights` when given,
/// else 8 lights extracted from the sequence's probe.hdr (a centred 180-degree fisheye looking up,
/// as `relight synth` writes it). Throws relight::Error when there is neither.
[[nodiscard]] lights::LightSet real_light_set(const std::filesystem::path& sequence,
                                              const std::filesystem::path& lights_file);

}  // namespace relight::app
