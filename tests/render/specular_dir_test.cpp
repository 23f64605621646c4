// DIR's reflective and refractive objects (Knecht et al., TVCG 2013 §4.1; specular_gbuffer.h,
// specular_shading.h): the secondary G-buffers against Snell's and Fresnel's closed forms, the
// shaded reflection against the path tracer, the real/virtual rule of eqs. 4-5, and the Vulkan
// renderer against the CPU twin.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "relight/colormap/color_space.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/dir.h"
#include "relight/render/dir/dir_vk.h"
#include "relight/render/dir/specular_gbuffer.h"
#include "relight/render/scene/specular_bsdf.h"
#include "relight/render/scene/tessellation.h"
#include "relight/render/vpl/vpl.h"
#include "relight/vk/context.h"
#include "specular_scenes.h"
#include "support/vulkan_test_env.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using Eigen::Vector3f;
using test::at;
using test::camera_at;
using test::slab_transmittance;
using test::specular_material;
using test::with_layer;

Vector3f ray_of(const MrCamera& camera, int row, int col) {
  return (camera.camera_to_world.linear() * camera.intrinsics.ray(col, row).normalized()).cast<float>();
}

Vector3f point_at(const PositionMap& map, int row, int col) {
  const Float3& p = map(row, col);
  return {p.x, p.y, p.z};
}

/// The lit real floor of test::floor_scene with a virtual mirror standing on it at x = 0.4,
/// facing -x (0.8 m wide, 0.8 m high), of normal-incidence reflectance `f0`.
MrScene mirror_scene(const Vector3f& f0, const Vector3f& light = {0.f, 0.f, 1.f}, float intensity = 2.f) {
  MrScene scene = test::floor_scene(Vector3f::Constant(0.5f), light, intensity);
  scene.meshes.push_back(
      with_layer(tessellate_rectangle({0.4f, 0, 0.4f}, {-1, 0, 0}, {0, 0.4f, 0}, {0, 0, 0.4f},
                                      scene.add_material(specular_material(conductor(f0), "mirror"))),
                 "mirror", false));
  return scene;
}

MrCamera mirror_camera(int width, int height) { return camera_at({-1.2, -0.3, 0.7}, {0.4, 0, 0.3}, width, height); }

/// Direct light only, without caustics unless a test asks for them: the path tracer misses the
/// caustics a mirror shows (E S D S L paths, caustic_light_tracer.h), and the closed forms leave them out.
DirRenderOptions direct_only() {
  DirRenderOptions options;
  options.shading.indirect = false;
  options.caustics.photons_per_light = 0;
  options.shadow_tile = 512;
  options.interleave = 1;
  return options;
}

TEST(SpecularGBuffer, AMirrorsReflectedRayEndsWhereTheMirroredRayMeetsTheFloor) {
  const Vector3f f0(0.9f, 0.6f, 0.3f);
  const MrScene scene = mirror_scene(f0);
  const MrCamera camera = mirror_camera(48, 36);
  const RayTracer tracer(scene);
  const GBuffer primary = gbuffer_cpu(tracer, camera);
  const SpecularGBuffers g = specular_gbuffers_cpu(tracer, camera, primary);
  int on_floor = 0, mirror_pixels = 0;
  for (int row = 0; row < 36; ++row)
    for (int col = 0; col < 48; ++col) {
      const bool mirror = primary.material(row, col) == 2;
      EXPECT_EQ(g.specular(row, col), mirror ? 1 : 0) << row << "," << col;
      if (!mirror) continue;
      ++mirror_pixels;
      const Vector3f d = ray_of(camera, row, col);
      const Vector3f expected_weight = schlick_fresnel(f0, std::abs(d.x()));
      EXPECT_TRUE(at(g.reflected.weight, row, col).isApprox(expected_weight, 1e-5f));
      EXPECT_EQ(at(g.refracted.weight, row, col), Vector3f::Zero());  // a mirror does not refract
      EXPECT_EQ(g.refracted.gbuffer.distance(row, col), 0.f);
      const Vector3f r(-d.x(), d.y(), d.z());  // mirrored in the plane x = 0.4
      const Vector3f on_mirror = point_at(primary.position, row, col);
      const Vector3f expected = on_mirror + r * (on_mirror.z() / -r.z());
      const float reach = expected.head<2>().cwiseAbs().maxCoeff();  // the floor ends at 2 m
      if (!(r.z() < 0.f) || reach > 1.98f) {
        // Past the floor's edge into the empty sky (at the edge itself, either).
        if (!(r.z() < 0.f) || reach > 2.02f) {
          EXPECT_EQ(g.reflected.gbuffer.distance(row, col), 0.f);
        }
        continue;
      }
      ASSERT_GT(g.reflected.gbuffer.distance(row, col), 0.f) << row << "," << col;
      EXPECT_LT((point_at(g.reflected.gbuffer.position, row, col) - expected).norm(), 1e-3f) << row << "," << col;
      EXPECT_EQ(g.reflected.gbuffer.virtual_surface(row, col), 0);  // the real floor
      EXPECT_LT((point_at(g.reflected.eye, row, col) - on_mirror).norm(), 1e-3f);
      ++on_floor;
    }
  EXPECT_EQ(g.pixels, mirror_pixels);
  EXPECT_GT(on_floor, 100);
}

TEST(SpecularGBuffer, AGlassSlabShiftsTheRefractedRayAndWeighsItByFresnelAndBeerLambert) {
  MrScene scene = test::floor_scene(Vector3f::Constant(0.5f), {0, 0, 2}, 1.f);
  const float ior = 1.5f, top = 0.6f, bottom = 0.5f;
  const Vector3f colour(0.5f, 0.8f, 1.f);
  const SpecularMaterial glass = dielectric(ior, colour, 0.1f);
  scene.meshes.push_back(with_layer(
      tessellate_box({-0.5f, -0.5f, bottom}, {0.5f, 0.5f, top}, scene.add_material(specular_material(glass, "glass"))),
      "slab", false));
  const MrCamera camera = camera_at({0, -1.2, 1.3}, {0, 0, 0}, 48, 36);
  const RayTracer tracer(scene);
  const GBuffer primary = gbuffer_cpu(tracer, camera);
  const SpecularGBuffers g = specular_gbuffers_cpu(tracer, camera, primary);
  int checked = 0;
  for (int row = 0; row < 36; ++row)
    for (int col = 0; col < 48; ++col) {
      const Vector3f entry = point_at(primary.position, row, col);
      if (!g.specular(row, col) || std::abs(entry.z() - top) > 1e-4f) continue;  // the top face only
      const Vector3f d = ray_of(camera, row, col);
      const float cos_i = -d.z();
      // Snell: the same horizontal direction, shortened by 1 / n; out again parallel to d.
      const Vector3f inside = refract(-d, Vector3f::UnitZ(), 1.f / ior).value();
      const float length = (top - bottom) / -inside.z();
      const Vector3f exit = entry + inside * length;
      if (std::abs(exit.x()) > 0.49f || std::abs(exit.y()) > 0.49f) continue;  // leaves through a side
      const Vector3f expected = exit + d * (exit.z() / -d.z());
      ASSERT_GT(g.refracted.gbuffer.distance(row, col), 0.f) << row << "," << col;
      EXPECT_LT((point_at(g.refracted.gbuffer.position, row, col) - expected).norm(), 2e-3f) << row << "," << col;
      const float f_in = dielectric_fresnel(cos_i, 1.f, ior), f_out = dielectric_fresnel(-inside.z(), ior, 1.f);
      // The eta^2 of entry and exit cancel; what is left is Fresnel twice and the absorption.
      const Vector3f expected_weight = (1.f - f_in) * (1.f - f_out) * beer_lambert(glass, length);
      EXPECT_TRUE(at(g.refracted.weight, row, col).isApprox(expected_weight, 2e-3f))
          << at(g.refracted.weight, row, col).transpose() << " vs " << expected_weight.transpose();
      EXPECT_NEAR(at(g.reflected.weight, row, col).x(), f_in, 1e-6f);
      EXPECT_EQ(g.reflected.gbuffer.distance(row, col), 0.f);  // reflected up into the empty sky
      ++checked;
    }
  EXPECT_GT(checked, 150);
}

TEST(SpecularGBuffer, LightCaughtInsideAGlassBallIsDroppedAfterItsLastVertex) {
  MrScene scene = test::floor_scene(Vector3f::Constant(0.5f), {0, 0, 2}, 1.f);
  scene.meshes.push_back(with_layer(
      tessellate_sphere({0, 0, 0.3f}, 0.2f, scene.add_material(specular_material(dielectric(1.5f), "glass"))), "ball",
      false));
  const MrCamera camera = camera_at({0, -1.0, 0.5}, {0, 0, 0.3}, 48, 36);
  const RayTracer tracer(scene);
  const GBuffer primary = gbuffer_cpu(tracer, camera);
  SpecularTraceOptions one;
  one.max_vertices = 1;  // the entry only: every refracted branch ends on the exit (glass) and is dropped
  const SpecularGBuffers clipped = specular_gbuffers_cpu(tracer, camera, primary, one);
  const SpecularGBuffers full = specular_gbuffers_cpu(tracer, camera, primary);
  ASSERT_GT(full.pixels, 100);
  int through = 0;
  for (int row = 0; row < 36; ++row)
    for (int col = 0; col < 48; ++col) {
      if (!full.specular(row, col)) continue;
      EXPECT_EQ(at(clipped.refracted.weight, row, col), Vector3f::Zero());
      const Vector3f w = at(full.refracted.weight, row, col);
      EXPECT_LE(w.maxCoeff(), 1.f);  // a clear ball only loses light to the reflections
      EXPECT_GE(w.minCoeff(), 0.f);
      through += full.refracted.gbuffer.distance(row, col) > 0.f;
    }
  EXPECT_GT(through, full.pixels / 2);  // most rays come out below and meet the floor
}

/// DIR (direct light) and the path tracer (without caustics: DIR's are a step of their own) over
/// the pixels whose 3 x 3 neighbourhood all see material label `label` (an outline's pixels are
/// partly something else in the path tracer).
struct InsideComparison {
  DifferentialImages dir;
  Eigen::Vector3d dir_sum = Eigen::Vector3d::Zero(), reference_sum = Eigen::Vector3d::Zero();
  std::vector<std::pair<int, int>> pixels;
};

InsideComparison compare_inside(const MrScene& scene, const MrCamera& camera, std::uint16_t label, int spp) {
  InsideComparison out;
  out.dir = render_dir_cpu(scene, camera, {}, direct_only());
  PathTracerOptions reference_options;
  reference_options.max_bounces = 0;
  reference_options.caustic_paths_per_pixel = 0.0;
  const DifferentialImages reference = render_reference(scene, camera, spp, reference_options);
  const GBuffer primary = gbuffer_cpu(RayTracer(scene), camera);
  for (int row = 1; row + 1 < camera.intrinsics.height; ++row)
    for (int col = 1; col + 1 < camera.intrinsics.width; ++col) {
      bool inside = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside = inside && primary.material(row + dy, col + dx) == label;
      if (!inside) continue;
      out.dir_sum += at(out.dir.real_virtual, row, col).cast<double>();
      out.reference_sum += at(reference.real_virtual, row, col).cast<double>();
      out.pixels.emplace_back(row, col);
    }
  return out;
}

TEST(SpecularDir, AVirtualMirrorShowsTheLitFloorAsThePathTracerDoes) {
  const InsideComparison c = compare_inside(mirror_scene(Vector3f(0.9f, 0.6f, 0.3f)), mirror_camera(48, 36), 2, 64);
  ASSERT_GT(c.pixels.size(), 150u);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.dir_sum[i] / c.reference_sum[i], 1.0, 0.03) << "channel " << i;
  EXPECT_GT(c.dir_sum.x(), 2.0 * c.dir_sum.z());  // the copper-coloured Fresnel
  // The floor and the lamp are real, and nothing virtual shades the floor the mirror shows:
  // L'_r = L'_rv (eq. 4).
  for (const auto& [row, col] : c.pixels)
    EXPECT_TRUE(at(c.dir.real, row, col).isApprox(at(c.dir.real_virtual, row, col), 1e-5f)) << row << "," << col;
}

// The refracted branch follows one path through the ball (the stronger lobe at every later
// vertex), the path tracer all of them: what the weaker lobes carry (internal reflections) is
// the difference left. Measured (48 x 36, 256 spp): 0.996 of the path tracer in every channel.
TEST(SpecularDir, AVirtualGlassBallShowsTheFloorBehindItAsThePathTracerDoes) {
  MrScene scene = test::floor_scene(Vector3f::Constant(0.5f), {0.3f, 0.4f, 1.2f}, 2.f);
  const SpecularMaterial glass = dielectric(1.5f, {0.6f, 0.9f, 0.7f}, 0.2f);
  scene.meshes.push_back(with_layer(
      tessellate_sphere({0, 0, 0.25f}, 0.2f, scene.add_material(specular_material(glass, "glass"))), "ball", false));
  const InsideComparison c = compare_inside(scene, camera_at({-0.2, -1.0, 0.6}, {0, 0, 0.2}, 48, 36), 2, 256);
  ASSERT_GT(c.pixels.size(), 100u);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.dir_sum[i] / c.reference_sum[i], 1.0, 0.05) << "channel " << i;
  std::cout << "glass ball, DIR / path tracer per channel: "
            << (c.dir_sum.array() / c.reference_sum.array()).transpose() << "\n";
}

// Eqs. 4-5: light of a virtual lamp, and a virtual object seen in the mirror, reach L'_rv only -
// in a virtual mirror and in a real one alike (Knecht et al. 2013 Fig. 7: the yellow box is seen
// in the real and in the virtual bottle).
class SpecularDirMirrorLayer : public ::testing::TestWithParam<bool> {};

TEST_P(SpecularDirMirrorLayer, OnlyRealLightOnRealSurfacesReachesTheReflectionsLr) {
  MrScene scene = mirror_scene(Vector3f::Ones());
  for (TriangleMesh& mesh : scene.meshes)
    if (mesh.name == "mirror") mesh.real = GetParam();
  scene.lights[0].real = false;
  test::add_virtual_box(scene, synth::Box{{-0.3, 0.0, 0.0}, {-0.1, 0.2, 0.2}},
                        test::diffuse({0.8f, 0.2f, 0.2f}, "box"));
  MrLight real_lamp;
  real_lamp.position = {-0.3f, -0.5f, 1.2f};
  real_lamp.intensity = Vector3f::Constant(1.f);
  scene.lights.push_back(real_lamp);
  const MrCamera camera = mirror_camera(48, 36);
  const DifferentialImages dir = render_dir_cpu(scene, camera, {}, direct_only());
  const RayTracer tracer(scene);
  const GBuffer primary = gbuffer_cpu(tracer, camera);
  const SpecularGBuffers g = specular_gbuffers_cpu(tracer, camera, primary);
  int box_seen = 0, floor_seen = 0;
  for (int row = 0; row < 36; ++row)
    for (int col = 0; col < 48; ++col) {
      if (!g.specular(row, col) || g.reflected.gbuffer.distance(row, col) == 0.f) continue;
      const Vector3f rv = at(dir.real_virtual, row, col), r = at(dir.real, row, col);
      if (g.reflected.gbuffer.virtual_surface(row, col)) {
        if (GetParam()) {
          EXPECT_GT(r.sum(), 0.f) << row << "," << col;  // a real mirror's L'_r: the real floor behind the box
        } else {
          EXPECT_EQ(r, Vector3f::Zero()) << row << "," << col;  // the virtual box: r(p_refl) false
        }
        box_seen += rv.sum() > 0.f;
      } else {
        // The real floor: L'_r has the real lamp's light only, L'_rv both lamps'.
        EXPECT_GT(rv.sum(), r.sum() * 1.05f) << row << "," << col;
        EXPECT_GT(r.sum(), 0.f) << row << "," << col;
        ++floor_seen;
      }
    }
  EXPECT_GT(box_seen, 5);
  EXPECT_GT(floor_seen, 50);
}

INSTANTIATE_TEST_SUITE_P(VirtualAndRealMirror, SpecularDirMirrorLayer, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) { return info.param ? "Real" : "Virtual"; });

// A virtual box seen in a real mirror takes the place of what the mirror shows behind it: L'_r
// there is the real world's reflection - the floor behind the box, exactly as the scene without
// the box has it - rather than eq. 4's zero, so Delta L' = box - floor and the composite shows
// the box instead of the box added to the camera's reflection of the floor.
TEST(SpecularDir, AVirtualBoxInARealMirrorReplacesTheFloorBehindIt) {
  MrScene without = mirror_scene(Vector3f::Ones());
  for (TriangleMesh& mesh : without.meshes)
    if (mesh.name == "mirror") mesh.real = true;
  MrScene scene = without;
  test::add_virtual_box(scene, synth::Box{{-0.3, 0.0, 0.0}, {-0.1, 0.2, 0.2}},
                        test::diffuse({0.8f, 0.2f, 0.2f}, "box"));
  const MrCamera camera = mirror_camera(48, 36);
  const DifferentialImages dir = render_dir_cpu(scene, camera, {}, direct_only());
  const DifferentialImages plain = render_dir_cpu(without, camera, {}, direct_only());
  const RayTracer tracer(scene);
  const SpecularGBuffers g = specular_gbuffers_cpu(tracer, camera, gbuffer_cpu(tracer, camera));
  int box_seen = 0;
  for (int row = 0; row < 36; ++row)
    for (int col = 0; col < 48; ++col) {
      if (!g.specular(row, col) || !g.reflected.gbuffer.virtual_surface(row, col)) continue;
      const Vector3f r = at(dir.real, row, col), floor = at(plain.real, row, col);
      ASSERT_GT(floor.sum(), 0.f) << row << "," << col;
      EXPECT_LT((r - floor).cwiseAbs().maxCoeff(), 1e-5f * floor.maxCoeff()) << row << "," << col;
      EXPECT_GT((at(dir.real_virtual, row, col) - r).cwiseAbs().sum(), 0.01f * floor.sum());  // the box, not the floor
      ++box_seen;
    }
  EXPECT_GT(box_seen, 5);
}

/// A camera image whose pixels tell where they are: linear red = x / width, green = y / height.
ColorImage position_coded(int width, int height) {
  ColorImage image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      image(y, x) =
          encode_srgb8({(x + 0.5f) / static_cast<float>(width), (y + 0.5f) / static_cast<float>(height), 0.5f});
  return image;
}

Vector3f centre_of_camera(const MrCamera& camera) { return camera.camera_to_world.translation().cast<float>(); }

Eigen::Vector2f project(const MrCamera& camera, const Vector3f& point) {
  const Eigen::Vector3d local = camera.camera_to_world.inverse() * point.cast<double>();
  return {static_cast<float>(camera.intrinsics.fx * local.x() / local.z() + camera.intrinsics.cx),
          static_cast<float>(camera.intrinsics.fy * local.y() / local.z() + camera.intrinsics.cy)};
}

// Eqs. 8-10 per branch: a reflected real surface the camera sees takes the camera's colour of it
// (where it projects), one hidden behind a real occluder or outside the image does not.
TEST(SpecularBackProjection, AMirrorTakesTheCameraImageOfWhatTheCameraItselfSees) {
  MrScene scene = mirror_scene(Vector3f::Constant(0.9f));
  // A real block hides the floor between it and the mirror from the camera, not from the mirror.
  test::add_virtual_box(scene, synth::Box{{-0.2, -0.2, 0.0}, {0.0, 0.2, 0.15}},
                        test::diffuse(Vector3f::Constant(0.5f)));
  scene.meshes.back().real = true;
  const MrCamera camera = mirror_camera(64, 48);
  GBuffer primary;
  SpecularBackProjection view;
  (void)render_dir_cpu(scene, camera, {}, direct_only(), &primary, &view);
  ASSERT_FALSE(view.empty());
  const RayTracer tracer(scene);
  int valid = 0, hidden = 0, outside = 0;
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      if (!view.specular(row, col)) continue;
      const Float3 source = view.reflected.camera_pixel(row, col);
      const Vector3f d = ray_of(camera, row, col);
      const Vector3f on_mirror = point_at(primary.position, row, col);
      const std::optional<SurfaceHit> seen = tracer.intersect(Layer::Real, on_mirror, Vector3f(-d.x(), d.y(), d.z()));
      if (!seen) continue;
      const Eigen::Vector2f p = project(camera, seen->point);
      const bool in_image = p.x() >= 0.f && p.y() >= 0.f && p.x() <= 63.f && p.y() <= 47.f;
      const Vector3f centre = camera.camera_to_world.translation().cast<float>();
      const Vector3f to_point = seen->point - centre;
      // The camera image has no virtual objects: only real surfaces hide a point from it.
      const bool occluded = tracer.occluded(Layer::Real, centre, to_point.normalized(), to_point.norm() * 0.98f);
      if (!in_image) {
        EXPECT_EQ(source.z, 0.f) << row << "," << col;
        ++outside;
      } else if (occluded) {
        ++hidden;
        EXPECT_EQ(source.z, 0.f) << row << "," << col;
      } else if (source.z > 0.f) {
        EXPECT_NEAR(source.x, p.x(), 1e-2f);
        EXPECT_NEAR(source.y, p.y(), 1e-2f);
        ++valid;
      }
    }
  EXPECT_GT(valid, 60);
  EXPECT_GT(hidden, 20);
  EXPECT_GT(outside, 5);
}

// The composite at the mirror: w CI(q) where the camera sees q and nothing virtual changes it,
// darker where the box shadows q, the rendering of the virtual box it reflects (r(q) false),
// the rendering where q is outside.
TEST(SpecularBackProjection, TheCompositeShowsTheCameraInTheMirrorAndRendersWhatTheCameraCannotSee) {
  MrScene scene = mirror_scene(Vector3f::Constant(0.9f));
  test::add_virtual_box(scene, synth::Box{{-0.3, 0.0, 0.0}, {-0.1, 0.2, 0.2}},
                        test::diffuse({0.8f, 0.2f, 0.2f}, "box"));
  const MrCamera camera = mirror_camera(64, 48);
  GBuffer primary;
  SpecularBackProjection view;
  const DifferentialImages images = render_dir_cpu(scene, camera, {}, direct_only(), &primary, &view);
  const ColorImage camera_image = position_coded(64, 48);
  const colormap::ToneMap exposure;
  const ColorImage plain =
      differential_composite(camera_image, images.real_virtual, images.real, images.virtual_coverage, exposure, {});
  const ColorImage seen = differential_composite(camera_image, images.real_virtual, images.real,
                                                 images.virtual_coverage, exposure, {.back_projection = &view});
  int camera_pixels = 0, shadowed_pixels = 0, box_pixels = 0;
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      if (!view.specular(row, col)) {
        EXPECT_EQ(seen(row, col), plain(row, col));  // elsewhere nothing changes
        continue;
      }
      const Float3 source = view.reflected.camera_pixel(row, col);
      const Float3 w = view.reflected.weight(row, col);
      const Float3 got = decode_srgb8(seen(row, col));
      if (source.z > 0.f) {
        // The camera's colour at the projection, times the mirror's Fresnel ...
        const Float3 expected{w.x * (source.x + 0.5f) / 64.f, w.y * (source.y + 0.5f) / 48.f, w.z * 0.5f};
        const Float3 rv = images.real_virtual(row, col), r = images.real(row, col);
        if (std::abs(rv.x - r.x) <= 1e-4f * std::max(r.x, 1.f)) {
          EXPECT_NEAR(got.x, expected.x, 0.02f) << row << "," << col;
          EXPECT_NEAR(got.y, expected.y, 0.02f) << row << "," << col;
          ++camera_pixels;
        } else {
          // ... darkened where the box shadows the floor the mirror shows (the camera sees that
          // floor lit: the box is not in its image).
          EXPECT_LT(rv.x, r.x) << row << "," << col;
          EXPECT_LT(got.x, expected.x + 0.01f) << row << "," << col;
          EXPECT_LT(got.y, expected.y + 0.01f) << row << "," << col;
          ++shadowed_pixels;
        }
      } else {
        // Rendered: TM(w L_r(q)) + TM(L'_rv) - TM(L'_r) = TM(L'_rv), up to rounding.
        const Float3 rendered = decode_srgb8(plain(row, col));
        EXPECT_NEAR(got.x, rendered.x, 0.01f) << row << "," << col;
        EXPECT_NEAR(got.y, rendered.y, 0.01f) << row << "," << col;
        box_pixels += images.real(row, col) == Float3{} && images.real_virtual(row, col).x > 0.f;
      }
    }
  EXPECT_GT(camera_pixels, 80);
  EXPECT_GT(shadowed_pixels, 0);
  EXPECT_GT(box_pixels, 5);
}

/// Solid angle of the square [-a, a]^2 seen from height h above its centre.
double square_solid_angle(double a, double h) { return 4.0 * std::atan(a * a / (h * std::sqrt(2.0 * a * a + h * h))); }

// §4.2.2: light that meets a mirror leaves no VPL on it but on the surface the mirrored path
// reaches. A lamp between the floor and a perfect ceiling mirror of the floor's size sends the
// floor its downward light directly and its upward light as from its mirror image, twice as
// high minus its own height: the flux of the VPLs of L_rv is I (Omega(h) + Omega(2 H - h)), that of
// L_r (no mirror) I Omega(h).
TEST(CausticVpls, APerfectCeilingMirrorSendsTheLampsUpwardLightToTheFloor) {
  const float lamp = 0.5f, ceiling = 1.f, intensity = 2.f;
  MrScene scene = test::floor_scene(Vector3f::Constant(0.5f), {0, 0, lamp}, intensity);
  scene.meshes.push_back(with_layer(tessellate_rectangle({0, 0, ceiling}, {0, 0, -1}, {2.f, 0, 0}, {0, 2.f, 0},
                                                         scene.add_material(specular_material(conductor(), "mirror"))),
                                    "mirror", false));
  VplOptions options;
  options.count = 8192;
  const std::vector<Vpl> vpls = generate_vpls(scene, RayTracer(scene), options);
  double real_virtual = 0.0, real = 0.0;
  for (const Vpl& vpl : vpls) {
    ASSERT_FALSE(scene.materials[vpl.material].specular.specular());  // none on the mirror
    EXPECT_NEAR(vpl.position.z(), 0.f, 1e-4f);
    if (vpl.in_real_virtual) real_virtual += vpl.flux.x();
    if (vpl.in_real) real += vpl.flux.x();
  }
  const double direct = intensity * square_solid_angle(2.0, lamp);
  const double mirrored = intensity * square_solid_angle(2.0, 2.0 * ceiling - lamp);
  EXPECT_NEAR(real, direct, 0.03 * direct);
  EXPECT_NEAR(real_virtual, direct + mirrored, 0.03 * (direct + mirrored));
}

// Eqs. 12-14: the sun through a virtual glass slab. The shadow maps see the slab as opaque; the
// caustic photons bring the transmitted light back into L_rv (their one followed path per photon
// misses the light reflected twice inside, a fraction R^2 of it); L_r, where the slab does not
// exist, keeps the sun alone. Measured (64 x 48, 65536 photons): 1.000 of the closed form under the
// slab (0.992 before the photons' directions were a rotated Hammersley set).
TEST(DirCaustics, AGlassSlabLetsTheSunThroughItIntoLrvOnly) {
  const float sun = 3.f, albedo = 0.5f;
  const Vector3f colour(0.5f, 0.8f, 1.f);
  const MrScene scene = test::sunlit_glass_slab(sun, albedo, colour);
  const MrCamera camera = camera_at({0, -1.6, 0.35}, {0, 0, 0}, 64, 48);
  DirRenderOptions options = direct_only();
  options.caustics.photons_per_light = 65536;
  options.caustics.radius = 0.03f;
  const DifferentialImages dir = render_dir_cpu(scene, camera, {}, options);
  DirRenderOptions without = options;
  without.caustics.photons_per_light = 0;
  const DifferentialImages dark = render_dir_cpu(scene, camera, {}, without);
  const auto under = test::floor_pixels(scene, camera, {-0.3f, -0.3f}, {0.3f, 0.3f});
  ASSERT_GT(under.size(), 60u);
  const double lit = albedo / std::numbers::pi * sun;
  test::expect_sun_through_slab(dir, under, lit, colour, 0.05, 1e-3);
  EXPECT_LT(test::mean_over(dark.real_virtual, under).maxCoeff(), 1e-3 * lit);  // without photons: the opaque shadow
  const Eigen::Vector3d through = test::mean_over(dir.real_virtual, under);
  std::cout << "slab caustic, DIR / closed form: " << through.x() / (lit * slab_transmittance(1.5f, colour.x()))
            << "\n";
}

// Knecht et al. 2013 Fig. 7's four combinations: a real or a virtual mirror under a real or a
// virtual lamp. The mirror (x = 0.4, facing -x) throws the lamp's light onto the floor as the
// lamp's mirror image at (0.8, 0, 1) would: (albedo / pi) I h / d^3 with h = 1 m and d the
// distance to the image. That caustic reaches L_rv always and L_r only when the lamp and the
// mirror are both real (eq. 14) - then the two cancel and DeltaL keeps nothing of it, since the
// camera image shows it already.
TEST(DirCaustics, FourCombinationsOfARealOrVirtualMirrorAndLamp) {
  const float albedo = 0.5f, intensity = 2.f;
  const Vector3f image(0.8f, 0.f, 1.f);
  const MrCamera camera = mirror_camera(64, 48);
  for (const bool real_mirror : {true, false})
    for (const bool real_lamp : {true, false}) {
      SCOPED_TRACE(std::string(real_mirror ? "real" : "virtual") + " mirror, " + (real_lamp ? "real" : "virtual") +
                   " lamp");
      MrScene scene = mirror_scene(Vector3f::Ones(), {0.f, 0.f, 1.f}, intensity);
      for (TriangleMesh& mesh : scene.meshes)
        if (mesh.name == "mirror") mesh.real = real_mirror;
      scene.lights[0].real = real_lamp;
      DirRenderOptions options = direct_only();
      options.caustics.photons_per_light = 65536;
      DirRenderOptions none = options;
      none.caustics.photons_per_light = 0;
      const DifferentialImages with = render_dir_cpu(scene, camera, {}, options);
      const DifferentialImages without = render_dir_cpu(scene, camera, {}, none);
      const auto pixels = test::floor_pixels(scene, camera, {-0.4f, -0.25f}, {0.2f, 0.25f});
      ASSERT_GT(pixels.size(), 100u);
      const GBuffer gbuffer = gbuffer_cpu(RayTracer(scene), camera);
      double expected = 0.0;
      for (const auto& [row, col] : pixels) {
        const Float3& p = gbuffer.position(row, col);
        const double d = (Vector3f(p.x, p.y, p.z) - image).norm();
        expected += albedo / std::numbers::pi * intensity / (d * d * d);
      }
      expected /= static_cast<double>(pixels.size());
      const double caustic_rv =
          (test::mean_over(with.real_virtual, pixels) - test::mean_over(without.real_virtual, pixels)).x();
      const double caustic_r = (test::mean_over(with.real, pixels) - test::mean_over(without.real, pixels)).x();
      std::cout << (real_mirror ? "real" : "virtual") << " mirror, " << (real_lamp ? "real" : "virtual")
                << " lamp: caustic in L_rv " << caustic_rv / expected << ", in L_r " << caustic_r / expected
                << " of the closed form\n";
      EXPECT_NEAR(caustic_rv, expected, 0.05 * expected);
      if (real_mirror && real_lamp) {
        EXPECT_NEAR(caustic_r, caustic_rv, 1e-6 * expected);  // the same photons in both worlds
      } else {
        EXPECT_LT(std::abs(caustic_r), 1e-9);
      }
    }
}

// A ball lens focuses a point light's rays below it: the brightest floor pixel lies on the axis,
// far brighter than the lamp alone makes it.
TEST(DirCaustics, AGlassBallFocusesALampBelowIt) {
  const float albedo = 0.5f, lamp = 1.5f;
  MrScene scene = test::floor_scene(Vector3f::Constant(albedo), {0, 0, lamp}, 1.f);
  // A ball lens's focal length from its centre is f = n R / (2 (n - 1)); the lamp at u above the
  // centre is imaged v = f u / (u - f) below it: with the centre at v, on the floor.
  const float radius = 0.1f, ior = 1.5f, f = ior * radius / (2.f * (ior - 1.f));
  const float centre = 0.5f * ((lamp)-std::sqrt(lamp * lamp - 4.f * f * lamp));  // c (lamp - c - f) = f (lamp - c)
  scene.meshes.push_back(with_layer(
      tessellate_sphere({0, 0, centre}, radius, scene.add_material(specular_material(dielectric(ior), "glass"))),
      "ball", false));
  const MrCamera camera = camera_at({0, -0.6, 0.4}, {0, 0, 0}, 96, 72);
  DirRenderOptions options = direct_only();
  options.caustics.photons_per_light = 65536;
  options.caustics.radius = 0.01f;
  const DifferentialImages dir = render_dir_cpu(scene, camera, {}, options);
  const RayTracer tracer(scene);
  float peak = 0.f, direct_there = 0.f;
  Vector3f peak_point = Vector3f::Zero();
  for (int row = 0; row < 72; ++row)
    for (int col = 0; col < 96; ++col) {
      const auto hit = test::pixel_hit(tracer, camera, row, col, Layer::Real);
      if (!hit || std::abs(hit->point.z()) > 1e-4f) continue;
      if (tracer.occluded(Layer::Virtual, centre_of_camera(camera),
                          (hit->point - centre_of_camera(camera)).normalized(),
                          (hit->point - centre_of_camera(camera)).norm()))
        continue;  // behind the ball
      if (dir.real_virtual(row, col).y > peak) {
        peak = dir.real_virtual(row, col).y;
        peak_point = hit->point;
        direct_there = dir.real(row, col).y;
      }
    }
  EXPECT_LT(peak_point.head<2>().norm(), 0.03f) << peak_point.transpose();
  EXPECT_GT(peak, 5.f * direct_there);
}

class SpecularDirVk : public relight::test::VulkanTest {};

TEST_F(SpecularDirVk, TheVulkanRendererShowsTheSameReflectionAsTheCpuTwin) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = mirror_scene(Vector3f(0.9f, 0.9f, 0.9f));
  const MrCamera camera = mirror_camera(64, 48);
  DirRenderOptions options = direct_only();
  options.shadow_tile = 256;
  const DifferentialImages cpu = render_dir_cpu(scene, camera, {}, options);
  DirRendererVk renderer(context, 64, 48);
  renderer.set_scene(scene, options);
  const DifferentialImages gpu = renderer.render(camera, {}, options);
  EXPECT_GT(renderer.last_timings().specular_ms, 0.0);
  const GBuffer& rasterised = renderer.last_gbuffer();
  double sum_cpu = 0.0, sum_gpu = 0.0;
  int pixels = 0;
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) {
      if (rasterised.material(row, col) != 2) continue;
      sum_cpu += at(cpu.real_virtual, row, col).sum();
      sum_gpu += at(gpu.real_virtual, row, col).sum();
      ++pixels;
    }
  ASSERT_GT(pixels, 300);
  EXPECT_NEAR(sum_gpu / sum_cpu, 1.0, 0.03);
}

}  // namespace
}  // namespace relight::render
