#include "relight/brdf/diffuse.h"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <numbers>
#include <span>

#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::brdf {

namespace {

float luminance(const Eigen::Vector3f& v) { return 0.2126f * v.x() + 0.7152f * v.y() + 0.0722f * v.z(); }

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

  [[nodiscard]] Eigen::Vector3f at(int column) const {
    return {shading_[0][column], shading_[1][column], shading_[2][column]};
  }
  /// The largest <omega_o . r_l> over the lights facing the pixel (-1 when none does).
  [[nodiscard]] float mirror(int column) const { return mirror_[column]; }

 private:
  Eigen::ArrayXf px_, py_, pz_, nx_, ny_, nz_, dx_, dy_, dz_, scale_, cosine_, n_dot_v_, inv_view_, mirror_, inv_d_,
      l_dot_v_;
  std::array<Eigen::ArrayXf, 3> shading_;
};

template <class Linear>
void estimate(int width, int height, Linear&& linear_at, const PositionMap& positions, const NormalMap& normals,
              const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  if (positions.width() != width || positions.height() != height || !positions.same_shape(normals)) {
    throw Error("brdf diffuse: colour, positions and normals must have the same size");
  }
  kd.resize(width, height);
  valid.resize(width, height);
  parallel_rows(height, options.threads, [&](int begin, int end) {
    RowShading shading(width);
    for (int r = begin; r < end; ++r) {
      shading.compute(positions.row(r), normals.row(r), lights);
      for (int c = 0; c < width; ++c) {
        kd(r, c) = {};
        valid(r, c) = 0;
        const Float3 p = positions(r, c), n = normals(r, c);
        if (!is_valid_normal(n) || !is_valid_depth(p.z)) continue;
        const Eigen::Vector3f colour = linear_at(r, c);
        if (luminance(colour) < options.min_brightness) continue;
        const Eigen::Vector3f d = shading.at(c);
        if (luminance(d) < options.min_shading || d.minCoeff() <= 0.f) continue;
        const Eigen::Vector3f k = colour.cwiseQuotient(d).cwiseMax(0.f).cwiseMin(options.max_kd);
        kd(r, c) = {k.x(), k.y(), k.z()};
        valid(r, c) = shading.mirror(c) > options.lobe_cos_min ? 2 : 1;
      }
    }
  }, 8);
}

}  // namespace

void estimate_diffuse(const ColorImage& color, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  estimate(
      color.width(), color.height(),
      [&](int r, int c) {
        const Rgb8 v = color(r, c);
        return Eigen::Vector3f(srgb8_to_linear(v.r), srgb8_to_linear(v.g), srgb8_to_linear(v.b));
      },
      positions, normals, lights, options, kd, valid);
}

void estimate_diffuse(const RadianceImage& linear, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid) {
  estimate(
      linear.width(), linear.height(),
      [&](int r, int c) {
        const Float3 v = linear(r, c);
        return Eigen::Vector3f(v.x, v.y, v.z);
      },
      positions, normals, lights, options, kd, valid);
}

}  // namespace relight::brdf
