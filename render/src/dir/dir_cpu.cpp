// shade_dir_from_maps(): the CPU mirror of dir_shade.comp (see dir_vk.h). Keep the two in step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/render/dir/dir.h"
#include "relight/render/dir/specular_shading.h"
#include "relight/render/scene/phong_brdf.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

/// No initialisers: the shading pass sets every field of every pixel, so its 640x480 of them
/// (18 MB) are allocated without a serial fill and first touched by the workers.
struct Radiance {
  Vec3 real_virtual;  ///< direct + emission
  Vec3 real;
  Vec3 indirect_real_virtual;  ///< this pixel's VPL subset, scaled by n^2
  Vec3 indirect_real;
};

/// The first pass's pixels, row-major.
class ShadedPixels {
 public:
  ShadedPixels(int width, int height)
      : width_(width),
        pixels_(std::make_unique_for_overwrite<Radiance[]>(static_cast<std::size_t>(width) *
                                                           static_cast<std::size_t>(height))) {}
  Radiance& operator()(int y, int x) { return pixels_[index(y, x)]; }
  const Radiance& operator()(int y, int x) const { return pixels_[index(y, x)]; }

 private:
  [[nodiscard]] std::size_t index(int y, int x) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }
  int width_;
  std::unique_ptr<Radiance[]> pixels_;
};

class MapShader {
 public:
  MapShader(const MrScene& scene, const ShadowLayout& layout, std::span<const float> shadow_atlas,
            std::span<const Vpl> vpls, std::span<const float> ism_atlas, const IsmPointPools& ism_points,
            const DirRenderOptions& options)
      : scene_(scene),
        shadows_(layout, shadow_atlas),
        vpls_(vpls),
        ism_(ism_atlas, options.ism, vpls, ism_points),
        first_emitter_(vpls.size() - emitter_count(vpls)),
        options_(options) {}

  /// Direct light with k_d textured by `kd_texture`; the indirect light with the surface's k_d
  /// before that texture, textured after the interleaved merge (merged_pixel), so that the merge's
  /// average over neighbouring pixels does not blur the texture into it. `m` is the surface's
  /// Phong (surface_phong(): its metallic-roughness texture applied; that, k_s and n vary
  /// slowly enough for the merge, and are not demodulated).
  /// `camera_distance`: of the point from the camera that measured it (real_surface_tolerance).
  [[nodiscard]] Radiance shade(const Vec3& point, const Vec3& normal, const Vec3& wo, const Phong& m,
                               const Vec3& kd_texture, const Vec3& emission, float real_pixel, std::uint32_t subset,
                               float camera_distance) const {
    Radiance out{emission, real_pixel * emission, Vec3::Zero(), Vec3::Zero()};
    const float tolerance =
        real_pixel > 0.f ? real_surface_tolerance(options_.shading.real_depth_noise_sigmas, camera_distance) : 0.f;
    if (options_.shading.direct)
      add_direct(point, normal, wo, with_kd_factor(m, kd_texture), real_pixel, tolerance, out);
    if (options_.shading.indirect) add_indirect(point, normal, wo, m, real_pixel, subset, out);
    return out;
  }

 private:
  [[nodiscard]] bool want_rv() const { return options_.output != DirOutput::RealOnly; }
  [[nodiscard]] bool want_r() const { return options_.output != DirOutput::RealVirtualOnly; }

  void add_direct(const Vec3& point, const Vec3& n, const Vec3& wo, const Phong& m, float real_pixel,
                  float real_tolerance, Radiance& out) const {
    for (std::size_t l = 0; l < scene_.lights.size(); ++l) {
      const MrLight& light = scene_.lights[l];
      if (light.through_vpl) continue;  // its emitter VPL lights the point (vpl.h)
      const std::optional<detail::LightSample> sample = detail::sample_light(light, point);
      if (!sample) continue;
      const float cos_i = sample->wi.dot(n);
      if (cos_i <= 0.f) continue;
      // The real layer's shadow first: no BRDF to evaluate where it is dark.
      const auto index = static_cast<std::uint32_t>(l);
      if (shadows_(index, 0, point, n, real_tolerance) == 0.f) continue;
      const Vec3 contribution = phong_brdf(m, n, sample->wi, wo).cwiseProduct(sample->irradiance) * cos_i;
      if (want_rv()) out.real_virtual += contribution * shadows_(index, 1, point, n);
      out.real += contribution * ((light.real ? 1.f : 0.f) * real_pixel);
    }
    // Emitter VPLs (vpl.h): direct light, so every pixel sees all of them (not interleaved).
    for (std::size_t j = first_emitter_; j < vpls_.size(); ++j) {
      const Vpl& vpl = vpls_[j];
      const bool in_rv = want_rv() && vpl.in_real_virtual;
      const bool in_r = want_r() && vpl.in_real && real_pixel > 0.f;
      const float cos_x = vpl.incident.dot(n);
      if ((!in_rv && !in_r) || cos_x <= 0.f) continue;
      const IsmLookup::Visibility seen = ism_(static_cast<std::uint32_t>(j), point);
      if (seen.real == 0.f) continue;
      const Vec3 contribution = vpl.flux.cwiseProduct(phong_brdf(m, n, vpl.incident, wo)) * cos_x;
      if (in_rv) out.real_virtual += contribution * seen.virtual_;
      if (in_r) out.real += contribution;
    }
  }

  void add_indirect(const Vec3& point, const Vec3& n, const Vec3& wo, const Phong& m, float real_pixel,
                    std::uint32_t subset, Radiance& out) const {
    const float min_distance2 = options_.shading.min_distance * options_.shading.min_distance;
    const auto count = static_cast<std::uint32_t>(first_emitter_);
    const auto subsets = static_cast<std::uint32_t>(options_.interleave * options_.interleave);
    Vec3 rv = Vec3::Zero(), r = Vec3::Zero();
    for (std::uint32_t j = subset; j < count; j += subsets) {
      const Vpl& vpl = vpls_[j];
      const bool in_rv = want_rv() && vpl.in_real_virtual;
      const bool in_r = want_r() && vpl.in_real && real_pixel > 0.f;
      if (!in_rv && !in_r) continue;
      const Vec3 to_vpl = vpl.position - point;
      const float distance2 = to_vpl.squaredNorm();
      if (!(distance2 > 0.f)) continue;
      const float distance = std::sqrt(distance2);
      const Vec3 wi = to_vpl / distance;
      const float cos_x = wi.dot(n), cos_y = -wi.dot(vpl.normal);
      if (cos_x <= 0.f || cos_y <= 0.f) continue;
      const IsmLookup::Visibility seen = ism_(j, -to_vpl, distance);
      if (seen.real == 0.f) continue;
      const Vec3 contribution = vpl.flux.cwiseProduct(phong_brdf(vpl_phong(scene_, vpl), vpl.normal, vpl.incident, -wi))
                                    .cwiseProduct(phong_brdf(m, n, wi, wo)) *
                                (cos_x * cos_y / std::max(distance2, min_distance2));
      if (in_rv) rv += contribution * seen.virtual_;
      if (in_r) r += contribution;
    }
    out.indirect_real_virtual = rv * static_cast<float>(subsets);
    out.indirect_real = r * static_cast<float>(subsets);
  }

  const MrScene& scene_;
  ShadowLookup shadows_;
  std::span<const Vpl> vpls_;
  IsmLookup ism_;
  std::size_t first_emitter_;  ///< vpls_[first_emitter_, end) are emitters
  const DirRenderOptions& options_;
};

/// Whether a neighbour may lend pixel (x, y) its indirect light: inside the image, on the same
/// kind of surface, within 5 % of its distance and with a normal within ~25 degrees. The pixel's
/// own G-buffer values are read once, not once per neighbour (the merge asks up to 135 times).
class SimilarTo {
 public:
  SimilarTo(const GBuffer& g, int x, int y)
      : g_(g),
        width_(g.distance.width()),
        height_(g.distance.height()),
        distance_(g.distance(y, x)),
        virtual_(g.virtual_surface(y, x) != 0),
        normal_(g.normal(y, x)) {}

  [[nodiscard]] bool operator()(int qx, int qy) const {
    if (qx < 0 || qy < 0 || qx >= width_ || qy >= height_) return false;
    const float dq = g_.distance(qy, qx);
    if (dq == 0.f || (g_.virtual_surface(qy, qx) != 0) != virtual_) return false;
    if (std::abs(dq - distance_) > 0.05f * distance_) return false;
    return dot(g_.normal(qy, qx), normal_) >= 0.9f;
  }

 private:
  const GBuffer& g_;
  int width_, height_;
  float distance_;
  bool virtual_;
  Float3 normal_;
};

/// Per column of one output row, the extremes over the merge window's n rows of what SimilarTo
/// compares (distance, virtual flag, normal), so that a pixel can tell from its window's
/// extremes, without comparing each neighbour, that all of them are similar (all_similar).
class WindowExtremes {
 public:
  WindowExtremes(const GBuffer& g, int n) : g_(g), n_(n), columns_(static_cast<std::size_t>(g.distance.width())) {}

  /// The columns' extremes for output row y; false when the window leaves the image there.
  bool set_row(int y) {
    const int top = y - n_ / 2, bottom = y + (n_ - n_ / 2) - 1;
    if (top < 0 || bottom >= g_.distance.height()) return false;
    for (std::size_t x = 0; x < columns_.size(); ++x) {
      Column c;
      for (int r = top; r <= bottom; ++r) {
        const int col = static_cast<int>(x);
        const float d = g_.distance(r, col);
        const float v = g_.virtual_surface(r, col) != 0 ? 1.f : 0.f;
        const Float3& normal = g_.normal(r, col);
        c.min_distance = std::min(c.min_distance, d);
        c.max_distance = std::max(c.max_distance, d);
        c.min_virtual = std::min(c.min_virtual, v);
        c.max_virtual = std::max(c.max_virtual, v);
        c.min_normal = {std::min(c.min_normal.x, normal.x), std::min(c.min_normal.y, normal.y),
                        std::min(c.min_normal.z, normal.z)};
        c.max_normal = {std::max(c.max_normal.x, normal.x), std::max(c.max_normal.y, normal.y),
                        std::max(c.max_normal.z, normal.z)};
        // min/max pass a NaN by, where SimilarTo compares it: such a window takes the slow path.
        if (std::isnan(d) || std::isnan(normal.x) || std::isnan(normal.y) || std::isnan(normal.z)) c.min_distance = 0.f;
      }
      columns_[x] = c;
    }
    return true;
  }

  /// Whether SimilarTo(g, x, y) holds for every pixel of the window around (x, y) (a drawn
  /// pixel): the distance test at the window's nearest and farthest distance, the normal test
  /// at a lower bound of every neighbour's dot product (float products and sums are monotone,
  /// so the bound holds for the rounded dot products too; the margin covers a compiler fusing
  /// one of them into a multiply-add). False sends the pixel to the neighbour-by-neighbour merge.
  [[nodiscard]] bool all_similar(int x, int y) const {
    const int left = x - n_ / 2, right = x + (n_ - n_ / 2) - 1;
    if (left < 0 || right >= static_cast<int>(columns_.size())) return false;
    Column w = columns_[static_cast<std::size_t>(left)];
    for (int q = left + 1; q <= right; ++q) {
      const Column& c = columns_[static_cast<std::size_t>(q)];
      w.min_distance = std::min(w.min_distance, c.min_distance);
      w.max_distance = std::max(w.max_distance, c.max_distance);
      w.min_virtual = std::min(w.min_virtual, c.min_virtual);
      w.max_virtual = std::max(w.max_virtual, c.max_virtual);
      w.min_normal = {std::min(w.min_normal.x, c.min_normal.x), std::min(w.min_normal.y, c.min_normal.y),
                      std::min(w.min_normal.z, c.min_normal.z)};
      w.max_normal = {std::max(w.max_normal.x, c.max_normal.x), std::max(w.max_normal.y, c.max_normal.y),
                      std::max(w.max_normal.z, c.max_normal.z)};
    }
    const float distance = g_.distance(y, x);
    if (w.min_distance == 0.f || w.min_virtual != w.max_virtual) return false;
    if (std::abs(w.min_distance - distance) > 0.05f * distance ||
        std::abs(w.max_distance - distance) > 0.05f * distance)
      return false;
    const Float3& normal = g_.normal(y, x);
    const Float3 extreme{normal.x >= 0.f ? w.min_normal.x : w.max_normal.x,
                         normal.y >= 0.f ? w.min_normal.y : w.max_normal.y,
                         normal.z >= 0.f ? w.min_normal.z : w.max_normal.z};
    return dot(extreme, normal) >= 0.9f + 1e-5f;
  }

 private:
  struct Column {
    float min_distance = std::numeric_limits<float>::max(), max_distance = 0.f;
    float min_virtual = 1.f, max_virtual = 0.f;
    Float3 min_normal{1.f, 1.f, 1.f}, max_normal{-1.f, -1.f, -1.f};
  };
  const GBuffer& g_;
  int n_;
  std::vector<Column> columns_;
};

/// merge_interleaved: dir_merge.comp's geometry-aware average of the indirect light, direct
/// light added unblurred. The n x n window holds one pixel of every VPL subset; a subset whose
/// pixel there is not similar is looked for one period further out (its 8 pixels at ±n), and
/// the found pixels of a subset are averaged first, so that every subset found counts once.
/// Without that search, a pixel next to an edge loses the same subsets as its neighbours, and
/// their indirect light shows as light or dark blocks.
/// `window_similar`: WindowExtremes::all_similar() said every neighbour is similar; the sum is
/// then the one below without its tests (the same additions in the same order).
Radiance merged_pixel(const GBuffer& g, const ShadedPixels& shaded, const RadianceImage& kd_texture, int x, int y,
                      int n, bool window_similar) {
  const Radiance& own = shaded(y, x);
  Vec3 sum_rv = own.indirect_real_virtual, sum_r = own.indirect_real;
  float weight = 1.f;
  if (n > 1 && window_similar) {
    for (int dy = -n / 2; dy < n - n / 2; ++dy)
      for (int dx = -n / 2; dx < n - n / 2; ++dx) {
        if (dx == 0 && dy == 0) continue;
        sum_rv += shaded(y + dy, x + dx).indirect_real_virtual;
        sum_r += shaded(y + dy, x + dx).indirect_real;
        weight += 1.f;
      }
  } else if (n > 1 && g.distance(y, x) != 0.f) {
    const SimilarTo similar(g, x, y);
    for (int dy = -n / 2; dy < n - n / 2; ++dy)
      for (int dx = -n / 2; dx < n - n / 2; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const int qx = x + dx, qy = y + dy;
        if (similar(qx, qy)) {
          sum_rv += shaded(qy, qx).indirect_real_virtual;
          sum_r += shaded(qy, qx).indirect_real;
          weight += 1.f;
          continue;
        }
        Vec3 subset_rv = Vec3::Zero(), subset_r = Vec3::Zero();
        float found = 0.f;
        for (int b = -1; b <= 1; ++b)
          for (int a = -1; a <= 1; ++a) {
            const int sx = qx + a * n, sy = qy + b * n;
            if ((a == 0 && b == 0) || !similar(sx, sy)) continue;
            subset_rv += shaded(sy, sx).indirect_real_virtual;
            subset_r += shaded(sy, sx).indirect_real;
            found += 1.f;
          }
        if (found == 0.f) continue;
        sum_rv += subset_rv / found;
        sum_r += subset_r / found;
        weight += 1.f;
      }
  }
  // The texture factor of k_d, applied to the indirect light after the merge (MapShader::shade).
  const Vec3 texture = texture_factor_at(kd_texture, x, y);
  Radiance out;
  out.indirect_real_virtual = (sum_rv / weight).cwiseProduct(texture);
  out.indirect_real = (sum_r / weight).cwiseProduct(texture);
  out.real_virtual = own.real_virtual + out.indirect_real_virtual;
  out.real = own.real + out.indirect_real;
  return out;
}

}  // namespace

namespace detail {

DifferentialImages shade_from_maps(const GBuffer& gbuffer, const MrScene& scene, const Vec3& camera_centre,
                                   const PositionMap* eyes, const ShadowLayout& layout,
                                   std::span<const float> shadow_atlas, std::span<const Vpl> vpls,
                                   std::span<const float> ism_atlas, const IsmPointPools& ism_points,
                                   const DirRenderOptions& options) {
  const int width = gbuffer.position.width(), height = gbuffer.position.height();
  if (shadow_atlas.size() < static_cast<std::size_t>(layout.atlas_width()) * static_cast<std::size_t>(layout.atlas_height()))
    throw Error("shade_dir_from_maps: the shadow atlas is smaller than its layout");
  const std::size_t ism_texels = 2 * vpls.size() * static_cast<std::size_t>(options.ism.tile) * static_cast<std::size_t>(options.ism.tile);
  if (ism_atlas.size() < ism_texels) throw Error("shade_dir_from_maps: the ISM atlas is smaller than its VPLs need");
  if (options.interleave < 1 || options.interleave > 8) throw Error("the interleave factor must be 1 to 8");
  const MapShader shader(scene, layout, shadow_atlas, vpls, ism_atlas, ism_points, options);
  const RadianceImage kd_texture = texture_factors(gbuffer, scene, MaterialTexture::BaseColor);
  const RadianceImage emission_texture = texture_factors(gbuffer, scene, MaterialTexture::Emission);
  const RadianceImage metallic_roughness = texture_factors(gbuffer, scene, MaterialTexture::MetallicRoughness);
  // Bent by normal maps for the shading; the merge compares the G-buffer's own normals.
  const NormalMap bent = shading_normals(gbuffer, scene);
  const NormalMap& normals = bent.empty() ? gbuffer.normal : bent;
  const Vec3 environment = scene.environment.radiance;
  const int n = options.interleave;
  ShadedPixels shaded(width, height);
  parallel_rows(height, options.shading.threads, [&](int begin, int end) {
    for (int y = begin; y < end; ++y)
      for (int x = 0; x < width; ++x) {
        if (gbuffer.distance(y, x) == 0.f) {
          shaded(y, x) = {environment, environment, Vec3::Zero(), Vec3::Zero()};
          continue;
        }
        const auto& p = gbuffer.position(y, x);
        const auto& nn = normals(y, x);
        const Vec3 point(p.x, p.y, p.z), normal(nn.x, nn.y, nn.z);
        const float real_pixel = gbuffer.virtual_surface(y, x) ? 0.f : 1.f;
        const auto subset = static_cast<std::uint32_t>(x % n + n * (y % n));
        const auto factor = [x, y](const RadianceImage& factors) { return texture_factor_at(factors, x, y); };
        const PhongMaterial& material = scene.materials[gbuffer.material(y, x) - 1u];
        const Vec3 eye = eyes ? Vec3((*eyes)(y, x).x, (*eyes)(y, x).y, (*eyes)(y, x).z) : camera_centre;
        shaded(y, x) =
            shader.shade(point, normal, (eye - point).normalized(), surface_phong(material, factor(metallic_roughness)),
                         factor(kd_texture), material.emission.cwiseProduct(factor(emission_texture)), real_pixel,
                         subset, (camera_centre - point).norm());
      }
  }, 4);
  DifferentialImages out{RadianceImage(width, height), RadianceImage(width, height), CoverageImage(width, height), 1,
                         RadianceImage(width, height), RadianceImage(width, height)};
  parallel_rows(
      height, options.shading.threads,
      [&](int begin, int end) {
        WindowExtremes window(gbuffer, n);
        for (int y = begin; y < end; ++y) {
          const bool window_in_image = n > 1 && window.set_row(y);
          for (int x = 0; x < width; ++x) {
            const bool similar = window_in_image && gbuffer.distance(y, x) != 0.f && window.all_similar(x, y);
            const Radiance r = merged_pixel(gbuffer, shaded, kd_texture, x, y, n, similar);
            out.real_virtual(y, x) = {r.real_virtual.x(), r.real_virtual.y(), r.real_virtual.z()};
            out.real(y, x) = {r.real.x(), r.real.y(), r.real.z()};
            out.indirect_real_virtual(y, x) = {r.indirect_real_virtual.x(), r.indirect_real_virtual.y(),
                                               r.indirect_real_virtual.z()};
            out.indirect_real(y, x) = {r.indirect_real.x(), r.indirect_real.y(), r.indirect_real.z()};
            out.virtual_coverage(y, x) = gbuffer.distance(y, x) != 0.f && gbuffer.virtual_surface(y, x) ? 1.f : 0.f;
          }
        }
      },
      8);
  return out;
}

}  // namespace detail

DifferentialImages shade_dir_from_maps(const GBuffer& gbuffer, const MrScene& scene, const Vec3& camera_centre,
                                       const ShadowLayout& layout, std::span<const float> shadow_atlas,
                                       std::span<const Vpl> vpls, std::span<const float> ism_atlas,
                                       const IsmPointPools& ism_points, const DirRenderOptions& options) {
  return detail::shade_from_maps(gbuffer, scene, camera_centre, nullptr, layout, shadow_atlas, vpls, ism_atlas,
                                 ism_points, options);
}

DifferentialImages render_dir_cpu(const MrScene& scene, const MrCamera& camera, std::span<const Vpl> vpls,
                                  const DirRenderOptions& options, GBuffer* gbuffer_out,
                                  SpecularBackProjection* back_projection_out) {
  const RayTracer tracer(scene);
  GBuffer local;
  GBuffer& gbuffer = gbuffer_out ? *gbuffer_out : local;
  gbuffer = gbuffer_cpu(tracer, camera, options.shading.threads);
  const ShadowLayout layout = plan_shadow_views(scene, options.shadow_tile);
  const std::vector<float> shadow_atlas =
      scene.coarse_real_meshes.empty()
          ? shadow_atlas_cpu(tracer, layout, options.shading.threads)
          : shadow_atlas_cpu(RayTracer(coarse_scene(scene)), layout, options.shading.threads);
  const IsmPointPools points = sample_ism_points(scene, options.ism);
  const std::vector<float> ism_atlas = ism_atlas_cpu(points, vpls, options.ism);
  DifferentialImages images = shade_dir_from_maps(gbuffer, scene, camera.camera_to_world.translation().cast<float>(),
                                                  layout, shadow_atlas, vpls, ism_atlas, points, options);
  SpecularBackProjection back_projection;
  if (has_specular_surfaces(scene))
    back_projection =
        add_specular_light(images, tracer, camera, gbuffer, layout, shadow_atlas, vpls, ism_atlas, points, options);
  if (back_projection_out) *back_projection_out = std::move(back_projection);
  return images;
}

}  // namespace relight::render
