#include "relight/render/dir/composite.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

#include "relight/colormap/color_space.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::render {

namespace {

void require_camera_size(const ColorImage& camera, std::initializer_list<const Image<Float3>*> radiance,
                         const CoverageImage& coverage) {
  bool same = camera.same_shape(coverage);
  for (const auto* image : radiance) same = same && camera.same_shape(*image);
  if (!same) throw Error("differential composite: the camera image and the rendered images differ in size");
}

/// The layer of composite_layer: c V and (1 - c) Delta per pixel. At a partly covered pixel
/// (0 < c < 1) with `virtual_centre`, V is the mean over the pixels of its 3x3 neighbourhood
/// (itself included) whose centre saw the virtual object, and Delta the mean over those whose
/// centre saw the real scene (none: its own V, or no Delta). So a blend never takes one pixel's
/// virtual shading as a real differential, and a sliver of a face that only the centre sample hit
/// (a side seen at a grazing angle) does not stand for the whole covered part of the pixel.
template <class VirtualColour, class Difference>
colormap::VirtualLayer separated_layer(const CoverageImage& coverage, const Mask* virtual_centre,
                                       const VirtualColour& virtual_colour, const Difference& difference) {
  const int width = coverage.width(), height = coverage.height();
  colormap::VirtualLayer layer{RadianceImage(width, height), coverage, RadianceImage(width, height)};
  const auto neighbours_mean = [&](int row, int col, bool want_virtual, const auto& value) -> std::optional<Float3> {
    Float3 sum;
    int n = 0;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j) {
        const int r = row + i, c = col + j;
        if (r < 0 || c < 0 || r >= height || c >= width) continue;
        if (((*virtual_centre)(r, c) != 0) != want_virtual) continue;
        sum += value(static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c));
        ++n;
      }
    if (n == 0) return std::nullopt;
    return (1.f / float(n)) * sum;
  };
  // Rows in parallel: a pixel reads its neighbours' inputs and writes only itself.
  parallel_for_each_row(height, 0, [&](int row) {
    for (int col = 0; col < width; ++col) {
      const std::size_t i =
          static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col);
      const float c = coverage.pixels()[i];
      Float3 v, d;
      if (c > 0.f) v = virtual_colour(i);
      if (c < 1.f) d = difference(i);
      if (virtual_centre && c > 0.f && c < 1.f) {
        v = neighbours_mean(row, col, true, virtual_colour).value_or(v);
        d = neighbours_mean(row, col, false, difference).value_or(Float3{});
      }
      layer.virtual_color.pixels()[i] = c * v;
      layer.delta.pixels()[i] = (1.f - c) * d;
    }
  });
  return layer;
}

/// The real differential of one channel: `with` - `without` (additive) or camera * (with /
/// without - 1) (multiplicative; additive where `without` is too dark for a ratio).
float real_difference(CompositeRule rule, float camera, float with, float without) {
  if (rule == CompositeRule::Additive || without < 1e-3f) return with - without;
  return camera * (std::min(with / without, kMaxCompositeRatio) - 1.f);
}

Float3 real_difference(CompositeRule rule, const Rgb8& camera, const Float3& with, const Float3& without) {
  if (rule == CompositeRule::Additive) return with - without;
  const Float3 c = colormap::decode_srgb8(camera);
  return {real_difference(rule, c.x, with.x, without.x), real_difference(rule, c.y, with.y, without.y),
          real_difference(rule, c.z, with.z, without.z)};
}

/// The camera's value at a real pixel where it clipped a channel (`linear`: the camera pixel
/// decoded), reconstructed from the rendered real radiance (composite.h); none where no channel is
/// clipped.
std::optional<Float3> unclipped_camera(const Rgb8& camera, const Float3& linear, const Float3& real, float scale) {
  const std::array<std::uint8_t, 3> code{camera.r, camera.g, camera.b};
  const std::array<float, 3> value{linear.x, linear.y, linear.z}, rendered{real.x, real.y, real.z};
  float camera_sum = 0.f, rendered_sum = 0.f;
  bool clipped = false;
  for (std::size_t k = 0; k < 3; ++k) {
    if (code[k] >= kClippedCode) {
      clipped = true;
    } else {
      camera_sum += value[k];
      rendered_sum += rendered[k];
    }
  }
  if (!clipped) return std::nullopt;
  // The render's brightness in camera units from the unclipped channels (all clipped: the scale).
  const float k = rendered_sum > 1e-6f ? camera_sum / rendered_sum : scale;
  std::array<float, 3> out = value;
  for (std::size_t c = 0; c < 3; ++c)
    if (code[c] >= kClippedCode) out[c] = std::max(value[c], k * rendered[c]);
  return Float3{out[0], out[1], out[2]};
}

/// The change of a real pixel whose camera value clipped: the reconstructed value scaled by the
/// rendered ratio L_rv / L_r, minus the camera's value; none where the camera did not clip (or the
/// objects change nothing there).
std::optional<Float3> clipped_difference(const Rgb8& camera, const Float3& with, const Float3& without, float scale) {
  if (with == without) return std::nullopt;
  const Float3 linear = colormap::decode_srgb8(camera);
  const std::optional<Float3> unclipped = unclipped_camera(camera, linear, without, scale);
  if (!unclipped) return std::nullopt;
  const auto ratio = [](float w, float wo) { return wo > 1e-6f ? std::min(w / wo, kMaxCompositeRatio) : 1.f; };
  const Float3 changed{unclipped->x * ratio(with.x, without.x), unclipped->y * ratio(with.y, without.y),
                       unclipped->z * ratio(with.z, without.z)};
  return changed - linear;
}

/// The camera image decoded to linear sRGB, bilinear at (x, y) inside it.
Float3 camera_linear_at(const ColorImage& camera, float x, float y) {
  const int x0 = std::clamp(static_cast<int>(x), 0, camera.width() - 1),
            y0 = std::clamp(static_cast<int>(y), 0, camera.height() - 1);
  const int x1 = std::min(x0 + 1, camera.width() - 1), y1 = std::min(y0 + 1, camera.height() - 1);
  const float fx = std::clamp(x - static_cast<float>(x0), 0.f, 1.f),
              fy = std::clamp(y - static_cast<float>(y0), 0.f, 1.f);
  const auto at = [&](int row, int col) { return colormap::decode_srgb8(camera(row, col)); };
  return (1.f - fy) * ((1.f - fx) * at(y0, x0) + fx * at(y0, x1)) + fy * ((1.f - fx) * at(y1, x0) + fx * at(y1, x1));
}

/// The back-projection of options, where it applies to `camera`'s pixels; none otherwise.
const SpecularBackProjection* back_projection_of(const CompositeOptions& options, const ColorImage& camera) {
  const SpecularBackProjection* view = options.back_projection;
  if (!view || view->empty()) return nullptr;
  if (!view->specular.same_shape(camera))
    throw Error("differential composite: the camera image and the specular back-projection differ in size");
  return view;
}

/// The virtual colour of a mirror or glass pixel (composite.h): CI_bp with the virtual objects'
/// change `with` - `without` (both in the composite's space) added or, multiplicatively, scaled in.
Float3 seen_through(CompositeRule rule, const Float3& camera_bp, const Float3& with, const Float3& without) {
  if (rule == CompositeRule::Additive) return camera_bp + (with - without);
  const auto channel = [](float camera, float w, float wo) {
    return wo < 1e-3f ? camera + (w - wo) : camera * std::min(w / wo, kMaxCompositeRatio);
  };
  return {channel(camera_bp.x, with.x, without.x), channel(camera_bp.y, with.y, without.y),
          channel(camera_bp.z, with.z, without.z)};
}

}  // namespace

ColorImage differential_composite(const ColorImage& camera, const RadianceImage& real_virtual,
                                  const RadianceImage& real, const CoverageImage& virtual_coverage,
                                  const colormap::ToneMap& tone_map, const CompositeOptions& options) {
  require_camera_size(camera, {&real_virtual, &real}, virtual_coverage);
  const auto to_camera = [&](const Float3& radiance) { return colormap::tone_map(radiance, tone_map); };
  const auto with = [&](std::size_t i) { return to_camera(real_virtual.pixels()[i]); };
  const auto difference = [&](std::size_t i) {
    const Float3 &lrv = real_virtual.pixels()[i], &lr = real.pixels()[i];
    if (const auto clipped = clipped_difference(camera.pixels()[i], lrv, lr, tone_map.exposure)) return *clipped;
    return real_difference(options.rule, camera.pixels()[i], with(i), to_camera(lr));
  };
  const SpecularBackProjection* view = back_projection_of(options, camera);
  const auto camera_at = [&](float x, float y) { return camera_linear_at(camera, x, y); };
  const auto virtual_colour = [&](std::size_t i) {
    if (!view || !view->specular.pixels()[i]) return with(i);
    return seen_through(options.rule, back_projected_camera(*view, i, camera_at, to_camera), with(i),
                        to_camera(real.pixels()[i]));
  };
  return colormap::composite_layer(
      camera, separated_layer(virtual_coverage, options.virtual_centre, virtual_colour, difference), options.look);
}

ColorImage mapped_differential_composite(const ColorImage& camera, const RadianceImage& delta,
                                         const RadianceImage& real_virtual, const RadianceImage& real,
                                         const CoverageImage& virtual_coverage, const colormap::ColorMapping& mapping,
                                         const CompositeOptions& options) {
  require_camera_size(camera, {&delta, &real_virtual, &real}, virtual_coverage);
  const auto mapped = [&](std::size_t i) { return mapping(real_virtual.pixels()[i]); };
  const SpecularBackProjection* view = back_projection_of(options, camera);
  const auto camera_at = [&](float x, float y) { return camera_linear_at(camera, x, y); };
  const auto to_camera = [&](const Float3& radiance) { return mapping(radiance); };
  const auto virtual_colour = [&](std::size_t i) {
    if (!view || !view->specular.pixels()[i]) return mapped(i);
    const Float3 with = mapped(i);
    return seen_through(options.rule, back_projected_camera(*view, i, camera_at, to_camera), with,
                        with - delta.pixels()[i]);
  };
  // delta_L = tau(TM(L_rv)) - tau(TM(L_r)) (colormap_stages.h), so tau(TM(L_r)) = mapped - delta.
  const auto difference = [&](std::size_t i) {
    if (const auto clipped = clipped_difference(camera.pixels()[i], real_virtual.pixels()[i], real.pixels()[i],
                                                mapping.tone_map.exposure))
      return *clipped;
    if (options.rule == CompositeRule::Additive) return delta.pixels()[i];
    const Float3 with = mapped(i);
    return real_difference(options.rule, camera.pixels()[i], with, with - delta.pixels()[i]);
  };
  return colormap::composite_layer(
      camera, separated_layer(virtual_coverage, options.virtual_centre, virtual_colour, difference), options.look);
}

}  // namespace relight::render
