#include "relight/capture/tag_layout.h"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"

namespace relight::capture {

namespace {

TagLayout::Tag parse_tag(const nlohmann::json& json) {
  TagLayout::Tag tag;
  tag.id = json.at("id").get<int>();
  tag.size = json.at("size").get<double>();
  const auto& corners = json.at("corners_world");
  if (!corners.is_array() || corners.size() != 4) throw Error("\"corners_world\" must list 4 corners");
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& corner = corners[k];
    if (!corner.is_array() || corner.size() != 3) throw Error("each corner must be [x, y, z]");
    tag.corners_world[k] = {corner[0].get<double>(), corner[1].get<double>(), corner[2].get<double>()};
  }
  if (!(tag.size > 0) || !std::isfinite(tag.size))
    throw Error("tag " + std::to_string(tag.id) + " needs a positive finite size");
  for (const auto& corner : tag.corners_world)
    if (!corner.allFinite()) throw Error("tag " + std::to_string(tag.id) + " has a corner that is not finite");
  return tag;
}

}  // namespace

const TagLayout::Tag* TagLayout::find(int id) const {
  for (const auto& tag : tags) {
    if (tag.id == id) return &tag;
  }
  return nullptr;
}

TagLayout parse_tag_layout(std::string_view json_text, const std::string& origin) {
  try {
    const auto json = nlohmann::json::parse(json_text);
    TagLayout layout;
    if (json.contains("tags")) {
      layout.family = json.value("family", "tag36h11");
      for (const auto& tag : json.at("tags")) layout.tags.push_back(parse_tag(tag));
    } else if (json.contains("tag")) {  // scene.json of `relight synth`
      layout.family = json["tag"].value("family", "tag36h11");
      layout.tags.push_back(parse_tag(json["tag"]));
    } else {
      throw Error("no \"tags\" list (or \"tag\" object of a scene.json)");
    }
    if (layout.family != "tag36h11") throw Error("family '" + layout.family + "' is not supported (tag36h11 is)");
    if (layout.tags.empty()) throw Error("the layout lists no tag");
    // The pose solver looks a detection up by id: a second entry with the same id would be
    // unreachable, and which one is "right" cannot be guessed.
    std::set<int> ids;
    for (const auto& tag : layout.tags)
      if (!ids.insert(tag.id).second) throw Error("tag " + std::to_string(tag.id) + " is listed twice");
    return layout;
  } catch (const nlohmann::json::exception& e) {
    throw Error(origin + ": bad tag layout: " + e.what());
  } catch (const Error& e) {
    throw Error(origin + ": bad tag layout: " + e.what());
  }
}

TagLayout read_tag_layout(const std::filesystem::path& file) {
  return parse_tag_layout(read_text_file(file), file.string());
}

}  // namespace relight::capture
