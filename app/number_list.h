#pragma once
// Option values that are comma-separated numbers ("x,y,z,intensity", "u,v,yaw"): one parser for
// every such option, so that each reports a bad field the same way.
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "relight/core/error.h"

namespace relight::app {

/// The numbers of `option`'s value `text` (empty text: none). A field that is not a finite number
/// throws relight::Error "OPTION 'text': 'field' is not a number", followed by " (expected
/// FORM)" when `expected` is given.
template <class T>
[[nodiscard]] std::vector<T> parse_number_list(std::string_view option, const std::string& text,
                                               std::string_view expected = {}) {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>);
  std::vector<T> values;
  std::stringstream stream(text);
  std::string field;
  while (std::getline(stream, field, ',')) {
    char* end = nullptr;
    T value;
    if constexpr (std::is_same_v<T, float>) {
      value = std::strtof(field.c_str(), &end);
    } else {
      value = std::strtod(field.c_str(), &end);
    }
    if (field.empty() || *end != '\0' || !std::isfinite(value)) {
      throw Error(std::string(option) + " '" + text + "': '" + field + "' is not a number" +
                  (expected.empty() ? std::string() : " (expected " + std::string(expected) + ")"));
    }
    values.push_back(value);
  }
  return values;
}

}  // namespace relight::app
