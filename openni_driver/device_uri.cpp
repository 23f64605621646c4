#include "device_uri.h"

#include <charconv>
#include <map>

#include "relight/core/error.h"

namespace relight::openni_driver {

namespace {

constexpr std::string_view kScheme = "relight://";

template <class T>
T parse_number(std::string_view uri, const std::string& key, const std::string& value) {
  T number{};
  const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), number);
  if (ec != std::errc() || end != value.data() + value.size()) {
    throw Error("device URI " + std::string(uri) + ": " + key + "=" + value + " is not a number");
  }
  return number;
}

std::map<std::string, std::string> parse_query(std::string_view uri, std::string_view query) {
  std::map<std::string, std::string> values;
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view item = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0) {
      throw Error("device URI " + std::string(uri) + ": '" + std::string(item) + "' is not key=value");
    }
    values[std::string(item.substr(0, eq))] = std::string(item.substr(eq + 1));
  }
  return values;
}

void apply(DeviceUri& device, std::string_view uri, const std::string& key, const std::string& value) {
  auto fail = [&](const std::string& why) {
    throw Error("device URI " + std::string(uri) + ": " + key + "=" + value + " " + why);
  };
  if (key == "fps") {
    device.fps = parse_number<double>(uri, key, value);
    if (!(device.fps > 0.0 && device.fps <= 1000.0)) fail("is outside (0, 1000]");
  } else if (key == "disconnect_after") {
    device.disconnect_after = parse_number<std::int64_t>(uri, key, value);
    if (device.disconnect_after < 0) fail("is negative");
  } else if (key == "reconnect_after") {
    device.reconnect_after = parse_number<std::int64_t>(uri, key, value);
    if (device.reconnect_after < 0 || device.reconnect_after > 1000000) fail("is outside [0, 1000000]");
  } else if (key == "seed") {
    device.seed = parse_number<std::uint64_t>(uri, key, value);
  } else if (key == "trajectory") {
    if (value != "static" && value != "orbit" && value != "handheld") fail("is not static, orbit or handheld");
    device.trajectory = value;
  } else if (key == "loop") {
    device.loop = parse_number<int>(uri, key, value);
    if (device.loop < 1 || device.loop > 100000) fail("is outside [1, 100000]");
  } else if (key == "noise") {
    if (value != "none" && value != "kinect1") fail("is not none or kinect1");
    device.noise = value == "kinect1";
  } else if (key == "size") {
    const auto x = value.find('x');
    if (x == std::string::npos) fail("is not WIDTHxHEIGHT");
    device.width = parse_number<int>(uri, key, value.substr(0, x));
    device.height = parse_number<int>(uri, key, value.substr(x + 1));
    if (device.width <= 0 || device.height <= 0) fail("is not a positive size");
  } else {
    throw Error("device URI " + std::string(uri) + ": unknown option '" + key +
                "' (fps, disconnect_after, reconnect_after, seed, trajectory, loop, noise, size)");
  }
}

}  // namespace

bool is_relight_uri(std::string_view uri) { return uri.substr(0, kScheme.size()) == kScheme; }

DeviceUri parse_device_uri(std::string_view uri) {
  if (!is_relight_uri(uri)) throw Error("device URI " + std::string(uri) + " does not start with relight://");
  DeviceUri device;
  device.text = std::string(uri);
  std::string_view rest = uri.substr(kScheme.size());
  const auto question = rest.find('?');
  const std::string_view query = question == std::string_view::npos ? std::string_view{} : rest.substr(question + 1);
  rest = rest.substr(0, question);
  if (rest == "synthetic") {
    device.kind = DeviceUri::Kind::Synthetic;
  } else if (rest.substr(0, 4) == "tum/" && rest.size() > 4) {
    device.kind = DeviceUri::Kind::Tum;
    device.folder = std::filesystem::path(std::string(rest.substr(4)));
  } else {
    throw Error("device URI " + std::string(uri) + ": expected relight://synthetic or relight://tum/<folder>");
  }
  for (const auto& [key, value] : parse_query(uri, query)) apply(device, uri, key, value);
  if (device.reconnect_after > 0 && device.disconnect_after == 0) {
    throw Error("device URI " + std::string(uri) + ": reconnect_after needs disconnect_after");
  }
  return device;
}

}  // namespace relight::openni_driver
