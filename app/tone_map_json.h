#pragma once
// The tone-mapping operator as report.json and render-reference's summary show it.
#include <cmath>
#include <nlohmann/json.hpp>

#include "relight/colormap/adaptive_tone_map.h"
#include "relight/core/named_values.h"

namespace relight::app {

/// The operator's options and, for Reinhard, the adaptation of the (last) frame `applied`.
inline nlohmann::ordered_json tone_map_json(const colormap::ToneMapOptions& options, const colormap::ToneMap& applied) {
  nlohmann::ordered_json json{{"operator", name_of(colormap::kToneOperatorNames, options.op)}};
  if (options.op == colormap::ToneOperator::Exposure) {
    json["exposure"] = options.exposure;
    return json;
  }
  json["key"] = options.key;
  json["adaptation_s"] = options.adaptation_s;
  json["log_average_luminance"] = applied.log_average_luminance;
  json["white"] = applied.white;
  json["scale"] = applied.exposure;  // key / log-average luminance
  json["scaled_white"] = applied.inverse_white_squared > 0.f ? 1.0 / std::sqrt(applied.inverse_white_squared) : 0.0;
  return json;
}

}  // namespace relight::app
