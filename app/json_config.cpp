#include "json_config.h"

#include <nlohmann/json.hpp>
#include <sstream>

namespace relight::app {

namespace {

// Sections (nested objects) address subcommands, which nest one level in relight. A file nested
// deeper than this is a mistake, and the bound keeps flatten()'s recursion off the end of the
// stack on a file of a million '{'s.
constexpr std::size_t kDeepestSection = 8;

// The error names the key rather than quoting the value: the value may be arbitrarily large and
// deep (printing it could overflow the stack too).
std::string scalar_text(const std::string& key, const nlohmann::json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  if (value.is_number() || value.is_null()) return value.dump();
  throw CLI::ConfigError("the value of '" + key + "' must be a string, number, boolean or array of those");
}

void flatten(const nlohmann::json& object, std::vector<std::string>& parents, std::vector<CLI::ConfigItem>& items) {
  for (const auto& [key, value] : object.items()) {
    if (value.is_object()) {
      if (parents.size() >= kDeepestSection)
        throw CLI::ConfigError("sections nest deeper than " + std::to_string(kDeepestSection) + " levels at '" + key + "'");
      parents.push_back(key);
      flatten(value, parents, items);
      parents.pop_back();
      continue;
    }
    CLI::ConfigItem item;
    item.parents = parents;
    item.name = key;
    if (value.is_array()) {
      for (const auto& element : value) item.inputs.push_back(scalar_text(key, element));
    } else {
      item.inputs.push_back(scalar_text(key, value));
    }
    items.push_back(std::move(item));
  }
}

}  // namespace

std::string JsonConfig::to_config(const CLI::App* app, bool default_also, bool, std::string) const {
  nlohmann::ordered_json json;
  for (const CLI::Option* option : app->get_options()) {
    if (option->get_lnames().empty() || !option->get_configurable()) continue;
    const std::string name = option->get_lnames().front();
    const auto results = option->results();
    if (!results.empty()) {
      json[name] = results.size() == 1 ? nlohmann::ordered_json(results.front()) : nlohmann::ordered_json(results);
    } else if (default_also && !option->get_default_str().empty()) {
      json[name] = option->get_default_str();
    }
  }
  return json.dump(2) + "\n";
}

std::vector<CLI::ConfigItem> JsonConfig::from_config(std::istream& input) const {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(input);
  } catch (const nlohmann::json::exception& e) {
    throw CLI::ConfigError(std::string("not valid JSON: ") + e.what());
  }
  if (!json.is_object()) throw CLI::ConfigError("must hold a JSON object");
  std::vector<CLI::ConfigItem> items;
  std::vector<std::string> parents;
  const auto selected = root_->get_subcommands();
  if (selected.size() == 1) parents.push_back(selected.front()->get_name());
  flatten(json, parents, items);
  return items;
}

void add_json_config(CLI::App& root) {
  root.set_config("--config", "", "JSON file with option values (keys = long flag names, e.g. {\"frames\": 30})");
  root.config_formatter(std::make_shared<JsonConfig>(&root));
}

}  // namespace relight::app
