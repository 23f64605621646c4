// `relight lights`: light sources from an HDR light probe (fisheye or lat-long), written as
// JSON, with a preview picture of the probe and the chosen lights (lights/light_output.h).
#include <Eigen/LU>
#include <cmath>
#include <iostream>
#include <numbers>

#include "commands.h"
#include "option_values.h"
#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/lights/light_output.h"
#include "relight/lights/light_stages.h"

namespace relight::app {

namespace {

/// --projection: the probe's, or auto (equirectangular when width = 2 x height, else fisheye).
enum class ProjectionChoice { Auto, Fisheye, Equirect };
constexpr std::array<NamedValue<ProjectionChoice>, 3> kProjectionChoiceNames{
    {{"auto", ProjectionChoice::Auto},
     {"fisheye", ProjectionChoice::Fisheye},
     {"equirect", ProjectionChoice::Equirect}}};

struct LightsCommandOptions {
  std::filesystem::path probe;
  int lights = 64;
  lights::LightMethod method = lights::LightMethod::Importance;
  std::uint64_t seed = 0;
  std::filesystem::path out;
  std::filesystem::path preview;
  ProjectionChoice projection = ProjectionChoice::Auto;
  std::vector<double> centre;
  double radius = 0.0;
  double fov = 180.0;
  std::vector<double> probe_to_world;
  double gamma = 2.2;
  bool quiet = false;
};

bool is_hdr_file(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  return ext == ".hdr" || ext == ".HDR" || ext == ".exr" || ext == ".EXR" || ext == ".pic";
}

// 8-bit pictures are linearised with a pure power law (the camera's inverse response).
RadianceImage read_probe(const std::filesystem::path& path, double gamma) {
  if (is_hdr_file(path)) return read_radiance(path);
  const ColorImage color = read_color(path);
  RadianceImage radiance(color.width(), color.height());
  auto linear = [gamma](std::uint8_t v) { return static_cast<float>(std::pow(v / 255.0, gamma)); };
  for (std::size_t i = 0; i < color.size(); ++i) {
    const Rgb8 c = color.pixels()[i];
    radiance.pixels()[i] = {linear(c.r), linear(c.g), linear(c.b)};
  }
  return radiance;
}

// A probe whose image circle is clipped white almost everywhere says nothing about where the
// light comes from (some clipped pixels - the sun, lamps - are normal). An 8-bit 255 linearises
// to exactly 1 and nothing else does, so the clipped pixels are those equal to (1, 1, 1).
void check_not_over_exposed(const RadianceImage& probe, const lights::ProbeGeometry& geometry,
                            const std::filesystem::path& file) {
  std::size_t seen = 0, clipped = 0;
  for (int row = 0; row < probe.height(); ++row) {
    for (int col = 0; col < probe.width(); ++col) {
      if (geometry.solid_angle(row, col) <= 0.f) continue;
      const Float3& p = probe(row, col);
      ++seen;
      clipped += p.x == 1.f && p.y == 1.f && p.z == 1.f ? 1 : 0;
    }
  }
  if (seen > 0 && static_cast<double>(clipped) >= 0.99 * static_cast<double>(seen)) {
    throw Error(file.string() + ": " + std::to_string(100 * clipped / seen) +
                " % of the probe is saturated (255): it is over-exposed, take it with a shorter exposure");
  }
}

lights::ProbeCalibration calibration_for(const LightsCommandOptions& command, const RadianceImage& probe) {
  const bool equirect = command.projection == ProjectionChoice::Auto ? probe.width() == 2 * probe.height()
                                                                     : command.projection == ProjectionChoice::Equirect;
  lights::ProbeCalibration calibration = equirect
                                             ? lights::ProbeCalibration::equirectangular()
                                             : lights::ProbeCalibration::centred_fisheye(probe.width(), probe.height());
  if (!command.centre.empty()) {
    calibration.fisheye.cx = command.centre[0];
    calibration.fisheye.cy = command.centre[1];
  }
  if (command.radius > 0.0) calibration.fisheye.radius = command.radius;
  calibration.fisheye.max_theta = command.fov / 2.0 * std::numbers::pi / 180.0;
  if (!command.probe_to_world.empty()) {
    Eigen::Matrix3d rotation;
    for (int i = 0; i < 9; ++i) rotation(i / 3, i % 3) = command.probe_to_world[static_cast<std::size_t>(i)];
    if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-3 || rotation.determinant() < 0) {
      throw Error("--probe-to-world is not a rotation matrix (9 numbers, row-major, orthonormal, det +1)");
    }
    calibration.probe_to_world = rotation;
  }
  return calibration;
}

int run_lights(const LightsCommandOptions& command) {
  const RadianceImage probe = read_probe(command.probe, command.gamma);
  lights::LightExtractionOptions options;
  options.method = command.method;
  options.lights = command.lights;
  options.seed = command.seed;
  options.calibration = calibration_for(command, probe);
  const lights::ProbeGeometry geometry(options.calibration, probe.width(), probe.height());
  if (!is_hdr_file(command.probe)) check_not_over_exposed(probe, geometry, command.probe);
  lights::LightSet lights;
  try {
    lights = lights::extract_lights(probe, options);
  } catch (const Error& error) {
    throw Error(command.probe.string() + ": " + error.what());
  }
  write_file_atomically(command.out, lights::lights_to_json(lights));
  if (!command.preview.empty()) write_color(command.preview, lights::light_preview(probe, geometry, lights));
  if (!command.quiet) {
    const Eigen::Vector3d e = irradiance(lights, Eigen::Vector3d::UnitZ());
    std::cerr << "relight lights: " << lights.lights.size() << " lights ("
              << name_of(lights::kLightMethodNames, command.method) << ") from " << command.probe.string()
              << ", irradiance on +z " << e.x() << " " << e.y() << " " << e.z() << " -> " << command.out.string()
              << "\n";
  }
  return 0;
}

}  // namespace

void register_lights(CLI::App& app, Runners& runners) {
  auto options = std::make_shared<LightsCommandOptions>();
  CLI::App* lights = app.add_subcommand("lights", "Extract light sources from an HDR light probe (fisheye or lat-long)");
  lights->add_option("probe", options->probe, "Probe image: .hdr/.exr (linear), or 8-bit (linearised with --gamma)")
      ->required();
  lights->add_option("--n", options->lights, "Number of lights")->check(CLI::Range(1, 1 << 20))->capture_default_str();
  add_choice_option(*lights, "--method", options->method, lights::kLightMethodNames,
                    "importance (hierarchical warping VPLs) or median-cut");
  lights->add_option("--seed", options->seed, "Rotation of the sample set (importance)")->capture_default_str();
  lights->add_option("--out", options->out, "Output JSON (lights/light_output.h)")->required();
  lights->add_option("--preview", options->preview, "Picture of the probe with the lights marked (.png)");
  add_choice_option(*lights, "--projection", options->projection, kProjectionChoiceNames,
                    "fisheye, equirect, or auto (equirect when width = 2 x height)");
  lights->add_option("--centre", options->centre, "Fisheye image-circle centre cx,cy in pixels (default: image centre)")
      ->expected(2)
      ->delimiter(',');
  lights->add_option("--radius", options->radius, "Fisheye image-circle radius in pixels at fov/2 (default: fits)")
      ->check(CLI::PositiveNumber);
  lights->add_option("--fov", options->fov, "Fisheye field of view in degrees")
      ->check(CLI::Range(1.0, 360.0))
      ->capture_default_str();
  lights->add_option("--probe-to-world", options->probe_to_world,
                     "Probe orientation: 3x3 rotation, row-major, 9 comma-separated numbers (default identity: "
                     "probe z = world up)")
      ->expected(9)
      ->delimiter(',');
  lights->add_option("--gamma", options->gamma, "Inverse response exponent for 8-bit probes")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  lights->add_flag("--quiet", options->quiet, "No summary on stderr");
  runners[lights] = [options] { return run_lights(*options); };
}

}  // namespace relight::app
