#include "relight/brdf/light_estimation.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "relight/brdf/kmeans.h"
#include "relight/brdf/shading.h"
#include "relight/core/parallel.h"
#include "relight/lights/light_set.h"
#include "relight/lights/probe_geometry.h"

namespace relight::brdf {

namespace {

using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;
constexpr double kMinIrradiance = 1e-4;
constexpr double kCauchyScale = 0.15;  // relative residual at which a sample's weight halves

/// The pixel may stand for diffuse reflection: measured, facing the camera, not a highlight, no
/// clipped channel, not black.
bool usable_pixel(const Rgb8& c, bool highlight, const Float3& p, const Float3& n) {
  if (highlight || p.z <= 0.f || !is_valid_normal(n)) return false;
  if (has_clipped_channel(c)) return false;
  if (static_cast<int>(c.r) + c.g + c.b < 6) return false;
  const float facing = -(n.x * p.x + n.y * p.y + n.z * p.z) / std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
  return facing > 0.2f;
}

Vector3d linear_rgb(const Rgb8& c) {
  const auto& table = srgb8_linear_table();
  return {table[c.r], table[c.g], table[c.b]};
}

Vector3d vec(const Float3& f) { return {f.x, f.y, f.z}; }

std::uint64_t voxel_key(const Vector3d& p, double size) {
  const auto cell = [&](double x) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(x / size)) & 0x1fffff);
  };
  return cell(p.x()) | (cell(p.y()) << 21) | (cell(p.z()) << 42);
}

std::vector<Vector3d> fibonacci_sphere(int count) {
  std::vector<Vector3d> out;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    out.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return out;
}

/// (2 half + 1)^2 directions around unit `d`, `step` radians apart.
std::vector<Vector3d> grid_around(const Vector3d& d, double step, int half) {
  const Vector3d t1 = d.unitOrthogonal();
  const Vector3d t2 = d.cross(t1);
  std::vector<Vector3d> out;
  for (int a = -half; a <= half; ++a) {
    for (int b = -half; b <= half; ++b)
      out.push_back((d + std::tan(a * step) * t1 + std::tan(b * step) * t2).normalized());
  }
  return out;
}

/// Screen-space shadow ray: whether the ray from camera-frame point `p` (normal `n`) towards `d`
/// passes behind a surface of the position map (within a 0.4 m thickness) before it leaves the
/// image or comes close to the camera.
/// std::lround's result for the pixel coordinates of the march (half away from zero), inline: the
/// library call was 14 % of the light estimate's time.
int round_to_pixel(double v) { return static_cast<int>(v < 0.0 ? v - 0.5 : v + 0.5); }

bool occluded(const PositionMap& positions, const PinholeIntrinsics& k, const Vector3d& p, const Vector3d& n,
              const Vector3d& d) {
  const Vector3d origin = p + 0.01 * n;
  double t = 0.02;
  for (int step = 0; step < 16; ++step, t *= 1.35) {
    const Vector3d x = origin + t * d;
    if (x.z() < 0.1) return false;
    const int col = round_to_pixel(k.fx * x.x() / x.z() + k.cx);
    const int row = round_to_pixel(k.fy * x.y() / x.z() + k.cy);
    if (!positions.in_bounds(row, col)) return false;
    const double z = positions(row, col).z;
    if (z <= 0.0) continue;
    const double gap = x.z() - z;
    if (gap > 0.015 + 0.01 * x.z() && gap < 0.4) return true;
  }
  return false;
}

Vector3d irradiance_floor(const Vector3d& e) { return e.cwiseMax(kMinIrradiance); }

/// The K-means feature of a reflectance: its chromaticity (r and g of r + g + b, doubled to
/// use the feature range), third component 0. Shading changes brightness but not chromaticity;
/// brightness would split one material by its shading wherever the light does not explain it yet
/// (a point light's falloff, shadows), so a black and a white material of one hue share a
/// cluster and the darker one counts as an outlier.
Float3 material_feature(const Vector3d& kd) {
  const double sum = std::max(kd.sum(), 1e-9);
  return kmeans_feature({static_cast<float>(2.0 * kd.x() / sum), static_cast<float>(2.0 * kd.y() / sum), 0.f});
}

/// Greedy merge of centres closer than `distance` (the larger cluster's centre stays); relabels.
void merge_close_centres(std::vector<Eigen::Vector3f>& centres, std::vector<std::uint8_t>& labels, float distance) {
  std::vector<double> count(centres.size(), 0.0);
  for (const std::uint8_t l : labels) count[l] += 1.0;
  std::vector<std::size_t> order(centres.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return count[a] > count[b]; });
  std::vector<int> target(centres.size(), -1);
  std::vector<Eigen::Vector3f> kept;
  for (const std::size_t c : order) {
    if (count[c] == 0.0) continue;
    for (std::size_t k = 0; k < kept.size() && target[c] < 0; ++k) {
      if ((kept[k] - centres[c]).norm() < distance) target[c] = static_cast<int>(k);
    }
    if (target[c] < 0) {
      target[c] = static_cast<int>(kept.size());
      kept.push_back(centres[c]);
    }
  }
  for (auto& l : labels) l = static_cast<std::uint8_t>(target[l]);
  centres = std::move(kept);
}

}  // namespace

const char* to_string(LightEvidence evidence) {
  switch (evidence) {
    case LightEvidence::Shading: return "shading";
    case LightEvidence::Shadows: return "shadows";
    case LightEvidence::None: break;
  }
  return "none";
}

lights::ShRgb LightEstimate::ambient_radiance() const {
  lights::ShRgb out = irradiance.irradiance_to_radiance();
  out -= lights::sh_of_directional_light(direction, power);
  return out;
}

nlohmann::ordered_json LightEstimate::to_json() const {
  const auto array = [](const Vector3d& v) { return nlohmann::ordered_json::array({v.x(), v.y(), v.z()}); };
  nlohmann::ordered_json j;
  j["evidence"] = to_string(evidence);
  j["direction"] = array(direction);
  j["power"] = array(power);
  j["irradiance_facing_light"] = array(irradiance_at(direction));
  j["shadow_share"] = shadow_share;
  j["shadow_frames"] = shadow_frames;
  j["voxels"] = voxels;
  j["fit_samples"] = fit_samples;
  j["fit_rms"] = fit_rms;
  auto& materials = j["materials"] = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < albedos.size(); ++i)
    materials.push_back({{"albedo", array(albedos[i])}, {"share", shares[i]}});
  return j;
}

LightEstimator::LightEstimator(LightEstimationOptions options)
    : options_(options), engine_(std::make_unique<KMeansCpu>(1)) {
  // A constant environment until the first fit.
  estimate_.irradiance.coefficients[0] = Vector3d::Constant(1.0 / lights::sh_basis(Vector3d::UnitZ())[0]);
}
LightEstimator::~LightEstimator() = default;
LightEstimator::LightEstimator(LightEstimator&&) noexcept = default;
LightEstimator& LightEstimator::operator=(LightEstimator&&) noexcept = default;

void LightEstimator::add_frame(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                               const NormalMap& normals, const PinholeIntrinsics& intrinsics,
                               const Pose& camera_to_world) {
  accumulate(color, highlights, positions, normals, camera_to_world);
  fit();
  fit_shadows(color, highlights, positions, normals, intrinsics, camera_to_world);
  if (shadow_weight_ > 0.0) {
    estimate_.evidence = LightEvidence::Shadows;
    estimate_.direction = shadow_direction_sum_.normalized();
    estimate_.power =
        (shadow_fraction_sum_ / shadow_weight_).cwiseProduct(estimate_.irradiance_at(estimate_.direction));
  } else {
    // The camera sees only some normals; band 1 extrapolated from them points off. The best-lit
    // normal that was seen is the light's direction for one light over an ambient.
    const lights::ShRgb radiance = estimate_.irradiance.irradiance_to_radiance();
    estimate_.evidence = LightEvidence::Shading;
    estimate_.direction = brightest_normal_;
    estimate_.power = lights::sh_directional_power(radiance, estimate_.direction);
  }
  // A surface facing the light receives at least the light.
  estimate_.power = estimate_.power.cwiseMax(0.0).cwiseMin(estimate_.irradiance_at(estimate_.direction).cwiseMax(0.0));
}

void LightEstimator::accumulate(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                                const NormalMap& normals, const Pose& camera_to_world) {
  const int stride = std::max(1, options_.stride);
  const Eigen::Matrix3d rotation = camera_to_world.linear();
  // What the camera looks at: the median world point of the image's central ninth.
  std::array<std::vector<double>, 3> central;
  for (int row = color.height() / 3; row < 2 * color.height() / 3; row += stride) {
    for (int col = color.width() / 3; col < 2 * color.width() / 3; col += stride) {
      if (positions(row, col).z <= 0.f) continue;
      const Vector3d world = camera_to_world * vec(positions(row, col));
      for (int a = 0; a < 3; ++a) central[static_cast<std::size_t>(a)].push_back(world[a]);
    }
  }
  if (!central[0].empty()) {
    Vector3d median;
    for (int a = 0; a < 3; ++a) {
      auto& values = central[static_cast<std::size_t>(a)];
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
      median[a] = values[values.size() / 2];
    }
    focus_sum_ += median;
    focus_frames_ += 1.0;
  }
  for (int row = stride / 2; row < color.height(); row += stride) {
    for (int col = stride / 2; col < color.width(); col += stride) {
      const Float3& p = positions(row, col);
      const Float3& n = normals(row, col);
      if (!usable_pixel(color(row, col), highlights && (*highlights)(row, col) != 0, p, n)) continue;
      const Vector3d world = camera_to_world * vec(p);
      const std::uint64_t key = voxel_key(world, options_.voxel_size);
      auto found = voxel_index_.find(key);
      if (found == voxel_index_.end()) {
        if (voxels_.size() >= options_.max_voxels) continue;
        found = voxel_index_.emplace(key, static_cast<std::uint32_t>(voxels_.size())).first;
        voxels_.emplace_back();
      }
      Voxel& voxel = voxels_[found->second];
      voxel.position_sum += world;
      voxel.colour_sum += linear_rgb(color(row, col));
      voxel.normal_sum += rotation * vec(n);
      voxel.count += 1.0;
    }
  }
  estimate_.voxels = voxels_.size();
}

double LightEstimator::locality(const Vector3d& world) const {
  if (focus_frames_ <= 0.0 || !(options_.locality_radius > 0.0)) return 1.0;
  const double r = options_.locality_radius;
  return std::exp(-(world - focus_sum_ / focus_frames_).squaredNorm() / (2.0 * r * r));
}

int LightEstimator::material_of(const Vector3d& colour, const Vector3d& world_normal) const {
  const Vector3d kd = kPi * colour.cwiseQuotient(irradiance_floor(estimate_.irradiance_at(world_normal)));
  const Float3 f = material_feature(kd);
  int best = 0;
  float best_distance = std::numeric_limits<float>::max();
  for (std::size_t c = 0; c < centres_.size(); ++c) {
    const float dx = f.x - centres_[c].x(), dy = f.y - centres_[c].y(), dz = f.z - centres_[c].z();
    const float distance = dx * dx + dy * dy + dz * dz;
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(c);
    }
  }
  return best;
}

void LightEstimator::fit() {
  std::vector<Sample> samples;
  const std::size_t step = std::max<std::size_t>(
      1, (voxels_.size() + options_.max_fit_samples - 1) / std::max<std::size_t>(1, options_.max_fit_samples));
  for (std::size_t i = 0; i < voxels_.size(); i += step) {
    const Voxel& v = voxels_[i];
    if (v.normal_sum.norm() < 0.5 * v.count) continue;  // normals that disagree: an edge
    samples.push_back({v.normal_sum.normalized(), v.colour_sum / v.count, locality(v.position_sum / v.count)});
  }
  estimate_.fit_samples = samples.size();
  const int clusters = std::clamp(options_.clusters, 1, 16);
  if (samples.size() < 4 * static_cast<std::size_t>(clusters)) return;

  std::vector<std::array<double, lights::kShCoefficients>> basis(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) basis[i] = lights::sh_basis(samples[i].normal);
  std::vector<double> weights(samples.size());
  double total_locality = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    weights[i] = samples[i].locality;
    total_locality += samples[i].locality;
  }
  std::vector<Float3> features(samples.size());
  std::vector<std::uint8_t> labels;
  std::vector<Vector3d> albedos;
  std::vector<double> shares;
  lights::ShRgb& sh = estimate_.irradiance;
  std::mt19937_64 rng(options_.seed);
  KMeansOptions kmeans_options;
  kmeans_options.clusters = clusters;
  kmeans_options.threads = 1;

  const int iterations = std::max(2, options_.iterations);
  for (int iteration = 0; iteration < iterations; ++iteration) {
    // k_d per sample with the current light, clustered into materials.
    for (std::size_t i = 0; i < samples.size(); ++i) {
      features[i] =
          material_feature(kPi * samples[i].colour.cwiseQuotient(irradiance_floor(sh.evaluate(samples[i].normal))));
    }
    engine_->set_points(features);
    KMeansResult result = kmeans(*engine_, features, kmeans_options, 2, rng);
    centres_ = std::move(result.centres);
    labels = std::move(result.labels);
    merge_close_centres(centres_, labels, static_cast<float>(options_.merge_distance));
    albedos.assign(centres_.size(), Vector3d::Zero());
    shares.assign(centres_.size(), 0.0);

    // Albedos given the light (weighted least squares per channel: I = rho E / pi).
    std::vector<Vector3d> num(albedos.size(), Vector3d::Zero()), den(albedos.size(), Vector3d::Zero());
    std::vector<double> count(albedos.size(), 0.0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const Vector3d e = irradiance_floor(sh.evaluate(samples[i].normal));
      num[labels[i]] += weights[i] * samples[i].colour.cwiseProduct(e);
      den[labels[i]] += weights[i] * e.cwiseProduct(e);
      count[labels[i]] += samples[i].locality;
    }
    for (std::size_t c = 0; c < albedos.size(); ++c) {
      albedos[c] = kPi * num[c].cwiseQuotient(den[c].cwiseMax(1e-12));
      shares[c] = count[c] / std::max(total_locality, 1e-12);
    }

    // The light given the albedos: one colour times a luminance environment (per-channel fits
    // would each have their own albedo/light scale and drift apart), 9 coefficients with a light
    // ridge on bands 1 and 2 so that normals no sample has leave the environment flat.
    Eigen::Matrix<double, 9, 9> normal_matrix = Eigen::Matrix<double, 9, 9>::Zero();
    Eigen::Matrix<double, 9, 1> rhs = Eigen::Matrix<double, 9, 1>::Zero();
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double a = lights::luminance(albedos[labels[i]].cwiseProduct(light_colour_)) / kPi;
      const Eigen::Map<const Eigen::Matrix<double, 9, 1>> y(basis[i].data());
      normal_matrix.noalias() += weights[i] * a * a * y * y.transpose();
      rhs.noalias() += weights[i] * a * lights::luminance(samples[i].colour) * y;
    }
    const double ridge = 1e-3 * std::max(normal_matrix(0, 0), 1e-12);
    for (int k = 1; k < 9; ++k) normal_matrix(k, k) += ridge;
    const Eigen::Matrix<double, 9, 1> environment = normal_matrix.ldlt().solve(rhs);
    const auto environment_at = [&](std::size_t i) {
      return std::max(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(basis[i].data()).dot(environment), kMinIrradiance);
    };

    // Scale and colour (white patch): the brightest few per cent of the samples' k_d (by
    // locality weight) are an achromatic white_albedo. A percentile, not a material's mean: a
    // white and a black material of one hue share a cluster.
    std::vector<std::pair<double, std::size_t>> brightness;  // k_d luminance, sample
    for (std::size_t i = 0; i < samples.size(); ++i) {
      brightness.emplace_back(kPi * lights::luminance(samples[i].colour) / environment_at(i), i);
    }
    std::sort(brightness.begin(), brightness.end());
    double above = 0.0, brightest = 0.0;
    Vector3d white_colour = Vector3d::Zero();
    for (auto it = brightness.rbegin(); it != brightness.rend(); ++it) {
      const double w = samples[it->second].locality;
      above += w;
      white_colour += w * kPi * samples[it->second].colour / environment_at(it->second);
      brightest = it->first;
      if (above >= options_.white_share * total_locality) break;
    }
    if (brightest > 0.0 && lights::luminance(white_colour) > 0.0) {
      light_colour_ = white_colour / lights::luminance(white_colour);
      const double s = options_.white_albedo / brightest;
      for (int k = 0; k < 9; ++k) sh.coefficients[static_cast<std::size_t>(k)] = (environment[k] / s) * light_colour_;
      for (auto& a : albedos) a *= s;
    }

    // Cauchy weights from the relative luminance residual.
    double weighted = 0.0, weight_sum = 0.0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double model = lights::luminance(albedos[labels[i]].cwiseProduct(sh.evaluate(samples[i].normal))) / kPi;
      const double r = (lights::luminance(samples[i].colour) - model) / std::max(model, 1e-4);
      weights[i] = samples[i].locality / (1.0 + (r / kCauchyScale) * (r / kCauchyScale));
      weighted += weights[i] * r * r;
      weight_sum += weights[i];
    }
    estimate_.fit_rms = std::sqrt(weighted / std::max(weight_sum, 1e-12));
  }
  estimate_.albedos = albedos;
  estimate_.shares = shares;
  double brightest = -1.0;
  for (const Sample& sample : samples) {
    const double e = lights::luminance(sh.evaluate(sample.normal));
    if (sample.locality > 0.1 && e > brightest) {
      brightest = e;
      brightest_normal_ = sample.normal;
    }
  }
}

void LightEstimator::fit_shadows(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                                 const NormalMap& normals, const PinholeIntrinsics& intrinsics,
                                 const Pose& camera_to_world) {
  estimate_.shadow_share = 0.0;
  if (centres_.empty() || estimate_.albedos.empty()) return;
  struct ShadowSample {
    Vector3d position, normal;  // camera frame
    Vector3d base;              // rho / pi
    double locality;
    Vector3d colour;              // linear RGB
    std::uint64_t neighbourhood;  // world cell, material and normal (see below)
  };
  std::vector<ShadowSample> samples;
  const int stride = std::max(1, options_.shadow_stride);
  const Eigen::Matrix3d rotation = camera_to_world.linear();
  for (int row = stride / 2; row < color.height(); row += stride) {
    for (int col = stride / 2; col < color.width(); col += stride) {
      const Float3& p = positions(row, col);
      const Float3& n = normals(row, col);
      if (!usable_pixel(color(row, col), highlights && (*highlights)(row, col) != 0, p, n)) continue;
      const Vector3d colour = linear_rgb(color(row, col));
      const Vector3d world_normal = rotation * vec(n);
      const int material = material_of(colour, world_normal);
      const Vector3d& rho = estimate_.albedos[static_cast<std::size_t>(material)];
      // Only the neighbourhood: far surfaces under other lamps' falloff mimic shadows.
      const double weight = locality(camera_to_world * vec(p));
      if (weight < 0.3) continue;
      // Neighbours: one 8 cm world cell, one material, normals in one 0.25-wide bucket.
      const Vector3d bucket = (world_normal * 4.0).array().round();
      const std::uint64_t neighbourhood = voxel_key(camera_to_world * vec(p), 0.08) ^
                                          (voxel_key(bucket, 1.0) * 0x9e3779b97f4a7c15ull) ^
                                          (static_cast<std::uint64_t>(material) << 58);
      samples.push_back({vec(p), vec(n), rho / kPi, weight, colour, neighbourhood});
    }
  }
  if (samples.empty()) return;
  // At most shadow_samples of them, evenly spread.
  const std::size_t keep_every = (samples.size() + static_cast<std::size_t>(std::max(1, options_.shadow_samples)) - 1) /
                                 static_cast<std::size_t>(std::max(1, options_.shadow_samples));
  if (keep_every > 1) {
    std::vector<ShadowSample> kept;
    for (std::size_t i = 0; i < samples.size(); i += keep_every) kept.push_back(samples[i]);
    samples = std::move(kept);
  }

  std::unordered_map<std::uint64_t, std::uint32_t> cell_of;
  std::vector<std::uint32_t> cells(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    cells[i] = cell_of.emplace(samples[i].neighbourhood, static_cast<std::uint32_t>(cell_of.size())).first->second;
  }
  // What the neighbourhoods leave unexplained: the squared error the shadow term can take a share of.
  double total_squared = 0.0;
  {
    std::vector<double> sum(cell_of.size(), 0.0), count(cell_of.size(), 0.0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      sum[cells[i]] += lights::luminance(samples[i].colour);
      count[cells[i]] += 1.0;
    }
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double r = lights::luminance(samples[i].colour) - sum[cells[i]] / count[cells[i]];
      total_squared += samples[i].locality * r * r;
    }
    if (total_squared <= 0.0) return;
  }

  // Least squares of the shadow term for direction d (camera frame). An occluded sample is
  // compared with the lit samples of its neighbourhood (same material, normal and place), not
  // with the SH: the SH cannot follow a near lamp's falloff or a glossy sheen, its neighbours do.
  struct Score {
    double share = 0.0;
    Vector3d rc = Vector3d::Zero(), cc = Vector3d::Zero();
    int compared = 0;
  };
  struct Scratch {
    std::vector<double> cosines;
    std::vector<char> shadowed;
    std::vector<Vector3d> lit_sum;
    std::vector<double> lit_count;
  };
  const auto score = [&](const Vector3d& world_direction, Scratch& scratch) {
    // A dominant light lies on the bright side of the environment: surfaces facing it receive
    // more than those facing away (this rules out "lights" below a table, whose darkness the
    // shadow term would otherwise explain).
    if (lights::luminance(estimate_.irradiance_at(world_direction)) <=
        lights::luminance(estimate_.irradiance_at(-world_direction))) {
      return Score{};
    }
    const Vector3d d = rotation.transpose() * world_direction;
    auto& [cosines, shadowed, lit_sum, lit_count] = scratch;
    cosines.resize(samples.size());
    shadowed.resize(samples.size());
    lit_sum.assign(cell_of.size(), Vector3d::Zero());
    lit_count.assign(cell_of.size(), 0.0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      cosines[i] = samples[i].normal.dot(d);
      shadowed[i] = cosines[i] > 0.1 && occluded(positions, intrinsics, samples[i].position, samples[i].normal, d);
      if (cosines[i] > 0.1 && !shadowed[i]) {
        lit_sum[cells[i]] += samples[i].colour;
        lit_count[cells[i]] += 1.0;
      }
    }
    Score s;
    double rc = 0.0, cc = 0.0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!shadowed[i] || lit_count[cells[i]] < 2.0) continue;
      const ShadowSample& sample = samples[i];
      const Vector3d residual = sample.colour - lit_sum[cells[i]] / lit_count[cells[i]];
      const Vector3d c = cosines[i] * sample.base;
      ++s.compared;
      s.rc += sample.locality * residual.cwiseProduct(c);
      s.cc += sample.locality * c.cwiseProduct(c);
      rc += sample.locality * lights::luminance(residual) * lights::luminance(c);
      cc += sample.locality * lights::luminance(c) * lights::luminance(c);
    }
    if (rc < 0.0 && cc > 0.0) s.share = rc * rc / cc / total_squared;
    return s;
  };
  // Every candidate of a batch scored in parallel, each worker with its own scratch.
  const auto score_all = [&](const std::vector<Vector3d>& directions) {
    std::vector<Score> scores(directions.size());
    parallel_rows(
        static_cast<int>(directions.size()), options_.threads,
        [&](int begin, int end) {
          Scratch scratch;
          for (int i = begin; i < end; ++i)
            scores[static_cast<std::size_t>(i)] = score(directions[static_cast<std::size_t>(i)], scratch);
        },
        8);
    return scores;
  };
  const std::vector<Vector3d> sphere = fibonacci_sphere(256);
  const std::vector<Score> sphere_scores = score_all(sphere);
  std::vector<std::pair<double, Vector3d>> coarse;
  for (std::size_t i = 0; i < sphere.size(); ++i) coarse.emplace_back(sphere_scores[i].share, sphere[i]);
  std::partial_sort(coarse.begin(), coarse.begin() + 3, coarse.end(),
                    [](const auto& a, const auto& b) { return a.first > b.first; });
  Vector3d best = coarse[0].second;
  Score best_score = sphere_scores[static_cast<std::size_t>(
      std::find_if(sphere.begin(), sphere.end(), [&](const Vector3d& d) { return d == best; }) - sphere.begin())];
  for (const double step_degrees : {3.0, 1.0}) {
    std::vector<Vector3d> candidates;
    if (step_degrees == 3.0) {
      for (int i = 0; i < 3; ++i) {
        const auto grid = grid_around(coarse[static_cast<std::size_t>(i)].second, step_degrees * kPi / 180.0, 2);
        candidates.insert(candidates.end(), grid.begin(), grid.end());
      }
    } else {
      candidates = grid_around(best, step_degrees * kPi / 180.0, 2);
    }
    const std::vector<Score> scores = score_all(candidates);
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (scores[i].share > best_score.share) {
        best_score = scores[i];
        best = candidates[i];
      }
    }
  }
  estimate_.shadow_share = best_score.share;
  if (best_score.share < options_.min_shadow_share || best_score.compared < options_.min_shadowed_samples) return;
  const Vector3d power = (-best_score.rc).cwiseQuotient(best_score.cc.cwiseMax(1e-12)).cwiseMax(0.0);
  const Vector3d fraction = power.cwiseQuotient(irradiance_floor(estimate_.irradiance_at(best)));
  shadow_direction_sum_ += best_score.share * best;
  shadow_fraction_sum_ += best_score.share * fraction;
  shadow_weight_ += best_score.share;
  ++estimate_.shadow_frames;
}

RadianceImage LightEstimator::environment_map() const {
  const int width = std::max(8, options_.map_width);
  const int height = width / 2;
  RadianceImage map = lights::sh_to_latlong(estimate_.ambient_radiance(), width, height);
  if (estimate_.power.maxCoeff() <= 0.0) return map;
  const lights::ProbeGeometry geometry(lights::ProbeCalibration::equirectangular(), width, height);
  const double cos_radius = std::cos(options_.light_radius_degrees * kPi / 180.0);
  std::vector<std::pair<int, int>> disc;
  double solid_angle = 0.0;
  std::pair<int, int> nearest{0, 0};
  double nearest_cos = -2.0;
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const double c = geometry.direction(col, row)->dot(estimate_.direction);
      if (c > nearest_cos) {
        nearest_cos = c;
        nearest = {row, col};
      }
      if (c >= cos_radius) {
        disc.emplace_back(row, col);
        solid_angle += geometry.solid_angle(row, col);
      }
    }
  }
  if (disc.empty()) {
    disc.push_back(nearest);
    solid_angle = geometry.solid_angle(nearest.first, nearest.second);
  }
  const Vector3d radiance = estimate_.power / std::max(solid_angle, 1e-12);
  for (const auto& [row, col] : disc) {
    map(row, col) +=
        Float3{static_cast<float>(radiance.x()), static_cast<float>(radiance.y()), static_cast<float>(radiance.z())};
  }
  return map;
}

}  // namespace relight::brdf
