#pragma once
// The names of an enum's values, written once, beside the enum: a table of (name, value) that
// serves to_string(), the CLI's choices and --help (app/option_values.h), the JSON config (which
// goes through the CLI), and the one parser that turns a text into the value, whose error lists
// the names.
//
//   inline constexpr std::array<NamedValue<PoseSource>, 4> kPoseSourceNames{{{"sequence", ...}, ...}};
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "relight/core/error.h"

namespace relight {

template <class E>
struct NamedValue {
  std::string_view name;  ///< a string literal (NUL-terminated, static storage)
  E value;
};

template <class E, std::size_t N>
[[nodiscard]] std::vector<std::string> names_of(const std::array<NamedValue<E>, N>& table) {
  std::vector<std::string> names;
  for (const auto& entry : table) names.emplace_back(entry.name);
  return names;
}

/// "a, b, c": the names for messages.
template <class E, std::size_t N>
[[nodiscard]] std::string name_list(const std::array<NamedValue<E>, N>& table) {
  std::string list;
  for (const auto& entry : table) list += (list.empty() ? "" : ", ") + std::string(entry.name);
  return list;
}

/// The value named `text`; throws relight::Error("WHAT 'text' is not one of a, b, c").
template <class E, std::size_t N>
[[nodiscard]] E parse_named(const std::array<NamedValue<E>, N>& table, std::string_view what, std::string_view text) {
  for (const auto& entry : table)
    if (entry.name == text) return entry.value;
  throw Error(std::string(what) + " '" + std::string(text) + "' is not one of " + name_list(table));
}

/// The name of `value` (NUL-terminated); a value missing from its table is a LogicError.
template <class E, std::size_t N>
[[nodiscard]] const char* name_of(const std::array<NamedValue<E>, N>& table, E value) {
  for (const auto& entry : table)
    if (entry.value == value) return entry.name.data();
  throw LogicError("a value without a name in its table");
}

}  // namespace relight
