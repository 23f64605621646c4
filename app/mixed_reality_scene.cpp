#include "mixed_reality_scene.h"

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "number_list.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/lights/light_output.h"
#include "relight/render/scene/model_io.h"
#include "relight/core/image_io.h"
#include "relight/lights/light_stages.h"

namespace relight::app {

namespace fs = std::filesystem;

bool is_synthetic(const fs::path& sequence) {
  const fs::path scene = sequence / "scene.json";
  if (!fs::is_regular_file(scene)) return false;
  const nlohmann::json json = nlohmann::json::parse(read_text_file(scene), nullptr, false);
  if (json.is_discarded()) throw Error(scene.string() + ": not valid JSON");
  return json.value("generator", std::string()) == "relight synth";
}

render::MrLight parse_virtual_light(const std::string& text) {
  const std::vector<float> v = parse_number_list<float>("--virtual-light", text);
  if (v.size() != 4 && v.size() != 7) throw Error("--virtual-light '" + text + "' needs x,y,z,intensity[,r,g,b]");
  render::MrLight light;
  light.kind = render::LightKind::Point;
  light.position = {v[0], v[1], v[2]};
  light.intensity = parse_intensity("--virtual-light", text, v, 3);
  light.real = false;
  return light;
}

render::MrLight parse_spot(const std::string& option, const std::string& text, bool real) {
  const std::vector<float> v = parse_number_list<float>(option.c_str(), text);
  const std::string what = option + " '" + text + "'";
  if (v.size() != 8 && v.size() != 11)
    throw Error(what + " needs x,y,z,target_x,target_y,target_z,angle_degrees,intensity[,r,g,b]");
  const Eigen::Vector3f position(v[0], v[1], v[2]);
  const Eigen::Vector3f axis = Eigen::Vector3f(v[3], v[4], v[5]) - position;
  if (!(axis.norm() > 1e-6f)) throw Error(what + ": the target is the light's position");
  if (!(v[6] > 0.f && v[6] < 90.f)) throw Error(what + ": the angle must be in (0, 90) degrees");
  return render::spot_light(position, axis.normalized(), v[6], kSpotInnerFraction * v[6],
                            parse_intensity(option.c_str(), text, v, 7), real);
}

render::VirtualModel load_model_telling_warnings(const fs::path& file) {
  render::VirtualModel model = render::load_model(file);
  for (const std::string& warning : model.warnings)
    std::cerr << "relight: warning: " << file.string() << ": " << warning << "\n";
  return model;
}

void check_real_places(const std::vector<fs::path>& objects, const std::vector<std::string>& places) {
  if (objects.size() != places.size())
    throw Error("--real-object: " + std::to_string(objects.size()) + " objects but " + std::to_string(places.size()) +
                " --real-place");
}

std::vector<std::pair<render::VirtualModel, render::Placement>> load_real_objects(
    const std::vector<fs::path>& objects, const std::vector<std::string>& places) {
  check_real_places(objects, places);
  std::vector<std::pair<render::VirtualModel, render::Placement>> out;
  for (std::size_t i = 0; i < objects.size(); ++i)
    out.emplace_back(load_model_telling_warnings(objects[i]), render::Placement::parse(places[i]));
  return out;
}

nlohmann::ordered_json real_objects_json(const std::vector<fs::path>& objects, const std::vector<std::string>& places) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < objects.size() && i < places.size(); ++i)
    out.push_back({{"model", objects[i].filename().string()}, {"place", places[i]}});
  return out;
}

lights::LightSet real_light_set(const fs::path& sequence, const fs::path& lights_file) {
  if (!lights_file.empty()) return lights::lights_from_json(read_text_file(lights_file), lights_file.string());
  const fs::path probe = sequence / "probe.hdr";
  if (!fs::is_regular_file(probe))
    throw Error(sequence.string() + " has no light probe: give its lights with --lights FILE (from `relight lights`)");
  const RadianceImage image = read_radiance(probe);
  lights::LightExtractionOptions options;
  options.lights = 8;
  options.calibration = lights::ProbeCalibration::centred_fisheye(image.width(), image.height());
  try {
    return lights::extract_lights(image, options);
  } catch (const Error& error) {
    throw Error(probe.string() + ": " + error.what());
  }
}

}  // namespace relight::app
