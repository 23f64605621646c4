#include "relight/brdf/diffuse.h"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <numbers>
#include <span>
#include <vector>

#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::brdf {

namespace {

/// D (shading.h) of one row, evaluated on structure-of-arrays columns so that the square roots
/// and divisions run vectorised; the same expression as diffuse_shading().
class RowShading {
 public:
  explicit RowShading(int width) {
    for (Eigen::ArrayXf* a : {&px_, &py_, &pz_, &nx_, &ny_, &nz_, &dx_, &dy_, &dz_, &scale_, &cosine_, &n_dot_v_,
                              &inv_view_, &mirror_, &inv_d_, &l_dot_v_}) {
      a->resize(width);
    }
    for (Eigen::ArrayXf& d : shading_) d.resize(width);
  }

  void compute(std::span<const Float3> positions, std::span<const Float3> normals, const ShadingLights& lights) {
    for (std::size_t c = 0; c < positions.size(); ++c) {
      const auto i = static_cast<Eigen::Index>(c);
      px_[i] = positions[c].x;
      py_[i] = positions[c].y;
      pz_[i] = positions[c].z;
      nx_[i] = normals[c].x;
      ny_[i] = normals[c].y;
      nz_[i] = normals[c].z;
    }
    constexpr float inv_pi = std::numbers::inv_pi_v<float>;
    for (int c = 0; c < 3; ++c) shading_[static_cast<std::size_t>(c)].setConstant(lights.ambient[c]);
    // omega_o = -p / |p|: <omega_o . r_l> = 2 <n.l> <n.omega_o> - <l.omega_o>.
    inv_view_ = (px_.square() + py_.square() + pz_.square()).sqrt().inverse();
    n_dot_v_ = -(nx_ * px_ + ny_ * py_ + nz_ * pz_) * inv_view_;
    mirror_.setConstant(-1.f);
    for (const ShadingLight& light : lights.lights) {
      if (light.point) {
        dx_ = light.vector.x() - px_;
        dy_ = light.vector.y() - py_;
        dz_ = light.vector.z() - pz_;
        scale_ = dx_.square() + dy_.square() + dz_.square();  // d^2
        inv_d_ = scale_.sqrt().inverse();
        dx_ *= inv_d_;
        dy_ *= inv_d_;
        dz_ *= inv_d_;
        scale_ = scale_.inverse();
      } else {
        dx_.setConstant(light.vector.x());
        dy_.setConstant(light.vector.y());
        dz_.setConstant(light.vector.z());
        scale_.setOnes();
      }
      cosine_ = nx_ * dx_ + ny_ * dy_ + nz_ * dz_;
      l_dot_v_ = -(dx_ * px_ + dy_ * py_ + dz_ * pz_) * inv_view_;
      mirror_ = (cosine_ > 0.f).select(mirror_.max(2.f * cosine_ * n_dot_v_ - l_dot_v_), mirror_);
      scale_ = (cosine_ > 0.f).select(scale_ * cosine_ * inv_pi, 0.f);
      for (int c = 0; c < 3; ++c) shading_[static_cast<std::size_t>(c)] += light.power[c] * scale_;
    }
  }

  [[nodiscard]] const std::array<Eigen::ArrayXf, 3>& shading() const { return shading_; }
  /// The largest <omega_o . r_l> over the lights facing the pixel (-1 when none does).
  [[nodiscard]] float mirror(int column) const { return mirror_[column]; }

 private:
  Eigen::ArrayXf px_, py_, pz_, nx_, ny_, nz_, dx_, dy_, dz_, scale_, cosine_, n_dot_v_, inv_view_, mirror_, inv_d_,
      l_dot_v_;
  std::array<Eigen::ArrayXf, 3> shading_;
};

/// k_d and validity of one row from its linear colour (structure of arrays) and shading.
class RowReflectance {
 public:
  explicit RowReflectance(int width) : geometry_(static_cast<std::size_t>(width)) {
    for (Eigen::ArrayXf& a : colour_) a.resize(width);
    for (Eigen::ArrayXf& a : kd_) a.resize(width);
  }
  std::array<Eigen::ArrayXf, 3>& colour() { return colour_; }

  void compute(int r, const PositionMap& positions, const NormalMap& normals, const RowShading& shading,
               const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
    const int width = static_cast<int>(geometry_.size());
    for (int c = 0; c < width; ++c) {
      geometry_[static_cast<std::size_t>(c)] = is_valid_normal(normals(r, c)) && is_valid_depth(positions(r, c).z);
    }
    const auto& d = shading.shading();
    const Eigen::ArrayXf lum_colour = 0.2126f * colour_[0] + 0.7152f * colour_[1] + 0.0722f * colour_[2];
    const Eigen::ArrayXf lum_shading = 0.2126f * d[0] + 0.7152f * d[1] + 0.0722f * d[2];
    const auto lit = (lum_colour >= options.min_brightness && lum_shading >= options.min_shading &&
                      d[0].min(d[1]).min(d[2]) > 0.f).eval();
    for (std::size_t ch = 0; ch < 3; ++ch) kd_[ch] = (colour_[ch] / d[ch]).max(0.f).min(options.max_kd);
    for (int c = 0; c < width; ++c) {
      const bool ok = geometry_[static_cast<std::size_t>(c)] && lit[c];
      kd(r, c) = ok ? Float3{kd_[0][c], kd_[1][c], kd_[2][c]} : Float3{};
      valid(r, c) = !ok ? 0 : shading.mirror(c) > options.lobe_cos_min ? 2 : 1;
    }
  }

 private:
  std::vector<std::uint8_t> geometry_;
  std::array<Eigen::ArrayXf, 3> colour_, kd_;
};

/// `fill_colour(r, colour)` writes row r's linear RGB into the three arrays.
template <class FillColour>
void estimate(int width, int height, FillColour&& fill_colour, const PositionMap& positions, const NormalMap& normals,
              const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  if (positions.width() != width || positions.height() != height || !positions.same_shape(normals)) {
    throw Error("brdf diffuse: colour, positions and normals must have the same size");
  }
  kd.resize(width, height);
  valid.resize(width, height);
  parallel_rows(height, options.threads, [&](int begin, int end) {
    RowShading shading(width);
    RowReflectance reflectance(width);
    for (int r = begin; r < end; ++r) {
      shading.compute(positions.row(r), normals.row(r), lights);
      fill_colour(r, reflectance.colour());
      reflectance.compute(r, positions, normals, shading, options, kd, valid);
    }
  }, 8);
}

}  // namespace

void estimate_diffuse(const ColorImage& color, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  const std::array<float, 256>& table = srgb8_linear_table();
  estimate(
      color.width(), color.height(),
      [&](int r, std::array<Eigen::ArrayXf, 3>& out) {
        const auto row = color.row(r);
        for (std::size_t c = 0; c < row.size(); ++c) {
          const auto i = static_cast<Eigen::Index>(c);
          out[0][i] = table[row[c].r];
          out[1][i] = table[row[c].g];
          out[2][i] = table[row[c].b];
        }
      },
      positions, normals, lights, options, kd, valid);
  for (std::size_t i = 0; i < color.size(); ++i) {
    const Rgb8 p = color.pixels()[i];
    if (valid.pixels()[i] == kKdMarkInvalid || std::max({p.r, p.g, p.b}) < options.clip_code) continue;
    valid.pixels()[i] = kKdMarkClipped;
    kd.pixels()[i] = {};
  }
}

void estimate_diffuse(const RadianceImage& linear, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  estimate(
      linear.width(), linear.height(),
      [&](int r, std::array<Eigen::ArrayXf, 3>& out) {
        const auto row = linear.row(r);
        for (std::size_t c = 0; c < row.size(); ++c) {
          const auto i = static_cast<Eigen::Index>(c);
          out[0][i] = row[c].x;
          out[1][i] = row[c].y;
          out[2][i] = row[c].z;
        }
      },
      positions, normals, lights, options, kd, valid);
}

}  // namespace relight::brdf
