// Normal maps (normal_map.h): tangent frames from texture coordinates, the G-buffer's one-float
// encoding, the bent normal, and the renderers shading with it against the closed form of a
// normal-mapped plane under a sun (glTF's normalTexture: texture_test.cpp).
#include "relight/render/scene/normal_map.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "relight/render/dir/dir.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/phong_brdf.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using Eigen::Vector3f;

/// The gradient (rows d u / d point, d v / d point) of coordinates u = a . p, v = b . p.
Eigen::Matrix<float, 2, 3> gradient(const Vector3f& a, const Vector3f& b) {
  Eigen::Matrix<float, 2, 3> g;
  g.row(0) = a.transpose();
  g.row(1) = b.transpose();
  return g;
}

TEST(NormalMap, TangentFramesFollowGltfsConvention) {
  // The textured square of the rendering tests: u grows with x, v with -y (v runs down the image).
  const auto frame = tangent_frame(gradient(Vector3f::UnitX(), -Vector3f::UnitY()), Vector3f::UnitZ());
  ASSERT_TRUE(frame);
  EXPECT_LT((frame->tangent - Vector3f::UnitX()).norm(), 1e-6f);
  EXPECT_EQ(frame->handedness, 1.f) << "B = N x T = +y, the direction of decreasing v";
  // Mirrored in u: the tangent turns round and the frame is left-handed, so B still points up v's decrease.
  const auto mirrored = tangent_frame(gradient(-Vector3f::UnitX(), -Vector3f::UnitY()), Vector3f::UnitZ());
  ASSERT_TRUE(mirrored);
  EXPECT_LT((mirrored->tangent + Vector3f::UnitX()).norm(), 1e-6f);
  EXPECT_EQ(mirrored->handedness, -1.f);
  EXPECT_LT((mirrored->handedness * Vector3f::UnitZ().cross(mirrored->tangent) - Vector3f::UnitY()).norm(), 1e-6f);
  // Sheared, stretched coordinates on a tilted plane: T is dP/du (v fixed), orthogonal to N.
  const Vector3f n = Vector3f(0.3f, -0.2f, 1.f).normalized();
  const Vector3f e1 = Vector3f::UnitX().cross(n).cross(n).normalized(), e2 = n.cross(e1);
  // u = 3 (p.e1) + (p.e2), v = 2 (p.e2): dP/du (v fixed) = e1 / 3.
  const auto sheared = tangent_frame(gradient(3.f * e1 + e2, 2.f * e2), n);
  ASSERT_TRUE(sheared);
  EXPECT_LT((sheared->tangent - e1).norm(), 1e-5f);
  EXPECT_FALSE(tangent_frame(gradient(Vector3f::UnitX(), Vector3f::UnitX()), Vector3f::UnitZ()))
      << "coordinates along one line do not span the surface";
}

TEST(NormalMap, TheGBufferEncodingRoundTrips) {
  EXPECT_FALSE(decode_tangent(0.f, Vector3f::UnitZ()));
  EXPECT_EQ(encode_tangent(std::nullopt, Vector3f::UnitZ()), 0.f);
  for (int i = 0; i < 200; ++i) {
    const float a = 0.37f * float(i), b = 0.11f * float(i) - 10.f;
    const Vector3f n = Vector3f(std::cos(a) * std::sin(b), std::sin(a) * std::sin(b), std::cos(b)).normalized();
    Vector3f t, s;
    orthonormal_basis(n, t, s);
    const float angle = 0.73f * float(i);
    const TangentFrame frame{std::cos(angle) * t + std::sin(angle) * s, i % 2 == 0 ? 1.f : -1.f};
    const auto decoded = decode_tangent(encode_tangent(frame, n), n);
    ASSERT_TRUE(decoded);
    EXPECT_LT((decoded->tangent - frame.tangent).norm(), 1e-5f) << i;
    EXPECT_EQ(decoded->handedness, frame.handedness) << i;
  }
}

TEST(NormalMap, TexelsBendTheNormalInTheFrame) {
  const Vector3f n = Vector3f::UnitZ();
  const TangentFrame frame{Vector3f::UnitX(), 1.f};
  EXPECT_LT((mapped_normal(n, frame, {0.5f, 0.5f, 1.f}, 1.f) - n).norm(), 1e-6f) << "the flat texel";
  const float a = 0.4f;
  const Vector3f towards_t(0.5f + 0.5f * std::sin(a), 0.5f, 0.5f + 0.5f * std::cos(a));
  EXPECT_LT((mapped_normal(n, frame, towards_t, 1.f) - Vector3f(std::sin(a), 0.f, std::cos(a))).norm(), 1e-6f);
  const Vector3f towards_b(0.5f, 0.5f + 0.5f * std::sin(a), 0.5f + 0.5f * std::cos(a));
  EXPECT_LT((mapped_normal(n, frame, towards_b, 1.f) - Vector3f(0.f, std::sin(a), std::cos(a))).norm(), 1e-6f);
  EXPECT_LT(
      (mapped_normal(n, {Vector3f::UnitX(), -1.f}, towards_b, 1.f) - Vector3f(0.f, -std::sin(a), std::cos(a))).norm(),
      1e-6f)
      << "left-handed";
  // The scale multiplies the tangential part: 0 flattens, 2 doubles the slope.
  EXPECT_LT((mapped_normal(n, frame, towards_t, 0.f) - n).norm(), 1e-6f);
  EXPECT_NEAR(mapped_normal(n, frame, towards_t, 2.f).x() / mapped_normal(n, frame, towards_t, 2.f).z(),
              2.f * std::tan(a), 1e-5f);
  // Seen from the back, the frame flips with the normal and the bent normal is the front's negated.
  EXPECT_LT((mapped_normal(-n, flipped(frame), towards_t, 1.f) + mapped_normal(n, frame, towards_t, 1.f)).norm(),
            1e-6f);
}

// ---- rendering ----------------------------------------------------------------------------------

constexpr float kSun = 2.f;
const Vector3f kSunDirection = Vector3f(0.5f, 0.3f, 1.f).normalized();
// Tilts of 30 degrees towards +x (red: T) and towards +y (green: B, up the image).
const Rgb8 kTiltT{192, 128, 239}, kTiltB{128, 192, 239};

Vector3f texel(const Rgb8& c) { return Vector3f(c.r, c.g, c.b) / 255.f; }

/// A virtual 1 m square at z = 0.2 facing up, k_d 0.8 (grey, untextured colour), coordinates
/// 0..1 across it as in texture_test.cpp, with a normal map of 4x4 cells tilting alternately
/// towards T and B, under a sun from kSunDirection.
MrScene normal_mapped_square() {
  MrScene scene;
  PhongMaterial material = test::diffuse({0.8f, 0.8f, 0.8f}, "bumpy");
  material.normal_texture =
      std::make_shared<const Texture>("normals", test::checkerboard(64, 16, kTiltT, kTiltB), TextureWrap::Repeat,
                                      TextureWrap::Repeat, TextureEncoding::Linear);
  TriangleMesh square;
  square.name = "square";
  square.real = false;
  square.positions = {{-0.5f, -0.5f, 0.2f}, {0.5f, -0.5f, 0.2f}, {0.5f, 0.5f, 0.2f}, {-0.5f, 0.5f, 0.2f}};
  square.normals.assign(4, Vector3f::UnitZ());
  square.texcoords = {{0.f, 1.f}, {1.f, 1.f}, {1.f, 0.f}, {0.f, 0.f}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  const std::uint32_t m = scene.add_material(material);
  square.triangle_material = {m, m};
  scene.meshes.push_back(square);
  MrLight sun;
  sun.kind = LightKind::Directional;
  sun.direction = kSunDirection;
  sun.intensity = Vector3f::Constant(kSun);
  sun.real = false;
  scene.lights.push_back(sun);
  return scene;
}

// Each cell's light is the Lambertian 0.8 / pi E (n' . l) of its own bent normal n', in DIR (the
// G-buffer's frame and the shading's bend) and in the path tracer (the hit's bend): the two tilts
// differ, so a swapped T/B or handedness shows.
TEST(NormalMappedRendering, EachCellIsLitAsItsBentNormalSays) {
  const MrScene scene = normal_mapped_square();
  const MrCamera camera = test::camera_at({0.05, -0.6, 1.4}, {0, 0, 0.2}, 80, 60);
  DirRenderOptions options;
  options.shadow_tile = 128;
  options.shading.indirect = false;
  GBuffer gbuffer;
  const DifferentialImages dir = render_dir_cpu(scene, camera, {}, options, &gbuffer);
  DifferentialPathTracer tracer(scene, {.max_bounces = 0});
  tracer.reset(camera);
  tracer.render(4);
  const DifferentialImages traced = tracer.images();
  ASSERT_FALSE(gbuffer.tangent.empty());
  const auto lit = [&](const Rgb8& c) {
    const Vector3f bent = (2.f * texel(c) - Vector3f::Ones()).normalized();  // T = +x, B = +y here
    return 0.8f / std::numbers::pi_v<float> * kSun * bent.dot(kSunDirection);
  };
  const float towards_t = lit(kTiltT), towards_b = lit(kTiltB),
              flat = 0.8f / std::numbers::pi_v<float> * kSun * kSunDirection.z();
  ASSERT_GT(std::abs(towards_t - towards_b), 0.05f * flat) << "the test needs the two tilts to differ";
  int cells[2] = {0, 0};
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      if (gbuffer.distance(y, x) == 0.f) continue;
      EXPECT_NEAR(gbuffer.normal(y, x).z, 1.f, 1e-6f) << "the G-buffer keeps the surface's own normal";
      const Float3& p = gbuffer.position(y, x);
      const float u = p.x + 0.5f, v = 0.5f - p.y;
      const float cu = u * 4.f - std::floor(u * 4.f), cv = v * 4.f - std::floor(v * 4.f);
      if (std::min({cu, cv, 1.f - cu, 1.f - cv}) < 0.15f) continue;
      const bool tilt_t = (static_cast<int>(u * 4.f) + static_cast<int>(v * 4.f)) % 2 == 0;
      const float expected = tilt_t ? towards_t : towards_b;
      ++cells[tilt_t ? 0 : 1];
      EXPECT_NEAR(dir.real_virtual(y, x).y, expected, 2e-3f * expected) << "DIR pixel " << x << "," << y;
      EXPECT_NEAR(traced.real_virtual(y, x).y, expected, 1e-2f * expected) << "path tracer pixel " << x << "," << y;
    }
  EXPECT_GT(cells[0], 100);
  EXPECT_GT(cells[1], 100);
}

}  // namespace
}  // namespace relight::render
