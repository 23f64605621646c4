#include "relight/lights/probe_response.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "relight/core/error.h"
#include "relight/core/srgb.h"

namespace relight::lights {

std::array<std::array<float, 256>, 3> ProbeResponse::srgb_inverse() {
  const std::array<float, 256>& channel = srgb8_linear_table();
  return {channel, channel, channel};
}

ProbeResponse read_probe_response(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read the probe response curve " + path.string());
  ProbeResponse response;
  std::string line;
  int code = 0;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t\r")] == '#') continue;
    const std::string where = path.string() + " line " + std::to_string(line_number);
    if (code == 256) throw Error(where + ": more than 256 code values");
    std::istringstream fields(line);
    std::array<double, 3> rgb{};
    if (!(fields >> rgb[0] >> rgb[1] >> rgb[2])) throw Error(where + ": expected three numbers r g b");
    for (std::size_t c = 0; c < 3; ++c) {
      if (!std::isfinite(rgb[c]) || rgb[c] < 0.0) throw Error(where + ": values must be finite and non-negative");
      auto& channel = response.inverse[c];
      if (code > 0 && rgb[c] < channel[static_cast<std::size_t>(code - 1)]) {
        throw Error(where + ": the curve decreases (a response is monotonic)");
      }
      channel[static_cast<std::size_t>(code)] = static_cast<float>(rgb[c]);
    }
    ++code;
  }
  if (code != 256) throw Error(path.string() + ": " + std::to_string(code) + " code values, expected 256");
  return response;
}

LdrProbe radiance_from_ldr(const ColorImage& image, const ProbeResponse& response) {
  if (!(response.exposure > 0.0) || !(response.clip_gain >= 1.0) || !(response.clip_threshold > 0.0) ||
      !(response.clip_threshold < 1.0)) {
    throw Error("probe response: exposure must be positive, the clip gain at least 1, the threshold in (0, 1)");
  }
  LdrProbe out{RadianceImage(image.width(), image.height()), 0.0};
  const double threshold = response.clip_threshold;
  std::size_t clipped = 0;
  const float scale = static_cast<float>(1.0 / response.exposure);
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Rgb8 code = image.pixels()[i];
    const double brightest = std::max({code.r, code.g, code.b}) / 255.0;
    float gain = scale;
    if (brightest > threshold) {
      ++clipped;
      const double s = (brightest - threshold) / (1.0 - threshold);
      gain *= static_cast<float>(1.0 + (response.clip_gain - 1.0) * s * s);
    }
    out.radiance.pixels()[i] = Float3{response.inverse[0][code.r] * gain, response.inverse[1][code.g] * gain,
                                      response.inverse[2][code.b] * gain};
  }
  out.clipped_share = image.size() ? static_cast<double>(clipped) / static_cast<double>(image.size()) : 0.0;
  return out;
}

}  // namespace relight::lights
