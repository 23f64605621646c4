#pragma once
// The values of a CLI option with a fixed set of them, written once: a table of (name, value)
// that serves CLI11's check (names_of), the parser that turns the text into its enum
// (parse_option: the one place an unknown name becomes an error) and the error message.
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "relight/core/error.h"

namespace relight::app {

template <class E>
struct OptionValue {
  std::string_view name;
  E value;
};

template <class E, std::size_t N>
[[nodiscard]] std::vector<std::string> names_of(const std::array<OptionValue<E>, N>& table) {
  std::vector<std::string> names;
  for (const auto& entry : table) names.emplace_back(entry.name);
  return names;
}

/// The value named `text`; throws relight::Error("OPTION 'text' is not one of a, b, c").
template <class E, std::size_t N>
[[nodiscard]] E parse_option(const std::array<OptionValue<E>, N>& table, std::string_view option, std::string_view text) {
  for (const auto& entry : table)
    if (entry.name == text) return entry.value;
  std::string list;
  for (const auto& entry : table) list += (list.empty() ? "" : ", ") + std::string(entry.name);
  throw Error(std::string(option) + " '" + std::string(text) + "' is not one of " + list);
}

}  // namespace relight::app
