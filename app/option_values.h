#pragma once
// CLI options whose values are an enum's names (core/named_values.h): the option stores the enum
// directly, CLI11 checks the text against the table (its error lists the names, --help shows them
// and the default), and the JSON config, which goes through CLI11, gets the same check. The text
// becomes the enum here, at the CLI boundary, and nowhere else.
#include <CLI/CLI.hpp>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>

#include "relight/core/named_values.h"

namespace relight::app {

/// `value` is an E, or a std::optional<E> that stays empty unless the option is given (no default
/// then).
template <class Value, class E, std::size_t N>
CLI::Option* add_choice_option(CLI::App& command, const std::string& flag, Value& value,
                               const std::array<NamedValue<E>, N>& table, const std::string& description) {
  CLI::Option* option = command.add_option_function<std::string>(
      flag, [&value, &table, flag](const std::string& text) { value = parse_named(table, flag, text); }, description);
  option->check(CLI::IsMember(names_of(table)));
  if constexpr (std::is_same_v<Value, E>) option->default_str(name_of(table, value));
  return option;
}

}  // namespace relight::app
