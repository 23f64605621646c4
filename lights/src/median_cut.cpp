#include "relight/lights/median_cut.h"

#include <array>
#include <cmath>
#include <numbers>
#include <queue>
#include <string>
#include <vector>

#include "relight/core/error.h"
#include "relight/lights/importance_sampling.h"

namespace relight::lights {

namespace {

// Summed-area tables of the importance w, of w * direction (for centroids) and of radiance x
// solid angle (for powers): any rectangle's sums in O(1).
class RegionSums {
 public:
  static constexpr int kChannels = 7;  // w, w*dx, w*dy, w*dz, L_r*omega, L_g*omega, L_b*omega

  RegionSums(const RadianceImage& probe, const ProbeGeometry& geometry)
      : width_(probe.width()), height_(probe.height()),
        table_(static_cast<std::size_t>(width_ + 1) * static_cast<std::size_t>(height_ + 1)) {
    for (int row = 0; row < height_; ++row) {
      std::array<double, kChannels> running{};
      for (int col = 0; col < width_; ++col) {
        const float omega = geometry.solid_angle(row, col);
        const double w = pixel_importance(probe(row, col), omega);
        if (w > 0.0) {
          const Eigen::Vector3d d = geometry.direction(col, row).value_or(Eigen::Vector3d::Zero());
          const Float3& l = probe(row, col);
          const std::array<double, kChannels> pixel{w, w * d.x(), w * d.y(), w * d.z(),
                                                   std::max(0.f, l.x) * static_cast<double>(omega),
                                                   std::max(0.f, l.y) * static_cast<double>(omega),
                                                   std::max(0.f, l.z) * static_cast<double>(omega)};
          for (int k = 0; k < kChannels; ++k) running[static_cast<std::size_t>(k)] += pixel[static_cast<std::size_t>(k)];
        }
        const auto& above = at(row, col + 1);
        auto& here = at(row + 1, col + 1);
        for (std::size_t k = 0; k < kChannels; ++k) here[k] = above[k] + running[k];
      }
    }
  }

  /// Sums over rows [r0, r1) and columns [c0, c1).
  [[nodiscard]] std::array<double, kChannels> sum(int r0, int r1, int c0, int c1) const {
    std::array<double, kChannels> s{};
    for (std::size_t k = 0; k < kChannels; ++k) s[k] = at(r1, c1)[k] - at(r0, c1)[k] - at(r1, c0)[k] + at(r0, c0)[k];
    return s;
  }
  [[nodiscard]] double energy(int r0, int r1, int c0, int c1) const { return sum(r0, r1, c0, c1)[0]; }

 private:
  [[nodiscard]] const std::array<double, kChannels>& at(int row, int col) const {
    return table_[static_cast<std::size_t>(row) * static_cast<std::size_t>(width_ + 1) + static_cast<std::size_t>(col)];
  }
  [[nodiscard]] std::array<double, kChannels>& at(int row, int col) {
    return table_[static_cast<std::size_t>(row) * static_cast<std::size_t>(width_ + 1) + static_cast<std::size_t>(col)];
  }
  int width_;
  int height_;
  std::vector<std::array<double, kChannels>> table_;
};

struct Region {
  int r0, r1, c0, c1;
  double energy;
  bool operator<(const Region& other) const { return energy < other.energy; }  // max-heap on energy
};

// The first index in (lo, hi) at which the energy before it reaches half; -1 if none splits.
template <class EnergyBefore>
int equal_energy_cut(int lo, int hi, double half, EnergyBefore energy_before) {
  if (hi - lo < 2) return -1;
  int low = lo + 1, high = hi - 1;
  while (low < high) {
    const int mid = (low + high) / 2;
    if (energy_before(mid) < half) low = mid + 1; else high = mid;
  }
  // Of the two neighbouring cuts, the one closer to equal halves.
  if (low > lo + 1 && std::abs(energy_before(low - 1) - half) < std::abs(energy_before(low) - half)) return low - 1;
  return low;
}

// Splits `region` in two across its longer side; false when it is a single pixel.
bool split(const Region& region, const RegionSums& sums, const ProbeGeometry& geometry, Region& a, Region& b) {
  double width = region.c1 - region.c0;
  const double height = region.r1 - region.r0;
  if (geometry.calibration().projection == ProbeProjection::Equirectangular) {
    const double theta = std::numbers::pi * (0.5 * (region.r0 + region.r1)) / geometry.height();
    width *= std::sin(theta);
  }
  const double half = region.energy / 2.0;
  const bool across_columns = (width >= height && region.c1 - region.c0 >= 2) || region.r1 - region.r0 < 2;
  if (across_columns) {
    const int cut = equal_energy_cut(region.c0, region.c1, half,
                                     [&](int c) { return sums.energy(region.r0, region.r1, region.c0, c); });
    if (cut < 0) return false;
    a = {region.r0, region.r1, region.c0, cut, sums.energy(region.r0, region.r1, region.c0, cut)};
    b = {region.r0, region.r1, cut, region.c1, sums.energy(region.r0, region.r1, cut, region.c1)};
  } else {
    const int cut = equal_energy_cut(region.r0, region.r1, half,
                                     [&](int r) { return sums.energy(region.r0, r, region.c0, region.c1); });
    if (cut < 0) return false;
    a = {region.r0, cut, region.c0, region.c1, sums.energy(region.r0, cut, region.c0, region.c1)};
    b = {cut, region.r1, region.c0, region.c1, sums.energy(cut, region.r1, region.c0, region.c1)};
  }
  return true;
}

}  // namespace

LightSet median_cut(const RadianceImage& probe, const ProbeGeometry& geometry, const MedianCutOptions& options) {
  if (options.lights <= 0) throw Error("median cut: the number of lights must be positive");
  if (!probe.same_shape(geometry)) {
    throw Error("light probe: image is " + std::to_string(probe.width()) + "x" + std::to_string(probe.height()) +
                " but its calibration is for " + std::to_string(geometry.width()) + "x" +
                std::to_string(geometry.height()));
  }
  const RegionSums sums(probe, geometry);
  const double total = sums.energy(0, probe.height(), 0, probe.width());
  if (!(total > 0.0) || !std::isfinite(total)) {
    throw Error("light probe: no light to sample (the image is black or not finite inside the image circle)");
  }
  std::priority_queue<Region> splittable;
  std::vector<Region> done;
  splittable.push({0, probe.height(), 0, probe.width(), total});
  while (!splittable.empty() && static_cast<int>(splittable.size() + done.size()) < options.lights) {
    const Region region = splittable.top();
    splittable.pop();
    Region a{}, b{};
    if (!split(region, sums, geometry, a, b)) {
      done.push_back(region);
      continue;
    }
    for (const Region& half : {a, b}) (half.energy > 0.0 ? splittable.push(half) : done.push_back(half));
  }
  while (!splittable.empty()) {
    done.push_back(splittable.top());
    splittable.pop();
  }

  LightSet set;
  for (const Region& region : done) {
    const auto s = sums.sum(region.r0, region.r1, region.c0, region.c1);
    const Eigen::Vector3d centroid(s[1], s[2], s[3]);
    if (!(s[0] > 0.0) || centroid.norm() == 0.0) continue;  // an empty region carries no light
    Light light;
    light.direction = centroid.normalized();
    light.power = {s[4], s[5], s[6]};
    set.lights.push_back(light);
  }
  return set;
}

}  // namespace relight::lights
