// Method 1 (normals_raw_depth.h) and its building blocks, against the synthetic scene's exact
// normals. The numbers quoted in comments were measured at 320x240 with Kinect v1 noise.
#include "relight/reconstruct/normals_raw_depth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "relight/core/frame_graph.h"
#include "relight/reconstruct/normal_error.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "synthetic_sequence.h"

namespace relight::reconstruct {
namespace {

// Exact plane z = z0 + a x (tilted about the camera's y axis) seen by a pinhole camera.
DepthMap tilted_plane(const PinholeIntrinsics& k, double z0, double slope) {
  DepthMap depth(k.width, k.height);
  for (int r = 0; r < k.height; ++r) {
    for (int c = 0; c < k.width; ++c) {
      // z = z0 + slope * x with x = (c - cx) z / fx  =>  z = z0 / (1 - slope (c - cx) / fx)
      depth(r, c) = static_cast<float>(z0 / (1.0 - slope * (c - k.cx) / k.fx));
    }
  }
  return depth;
}

PinholeIntrinsics small_camera() { return {.fx = 100, .fy = 100, .cx = 39.5, .cy = 29.5, .width = 80, .height = 60}; }

TEST(NormalsFromPositions, TiltedPlaneGivesItsExactNormalTowardsTheCamera) {
  const PinholeIntrinsics k = small_camera();
  const DepthMap depth = tilted_plane(k, 2.0, 0.5);
  PositionMap positions;
  positions_from_depth(depth, k, positions);
  EXPECT_NEAR(positions(10, 20).x, (20 - k.cx) / k.fx * depth(10, 20), 1e-6);
  for (int stride : {1, 4}) {
    NormalMap normals;
    normals_from_positions(positions, normals, {.stride = stride});
    // Plane z - 0.5 x = 2: normal ∝ (-0.5, 0, 1), flipped towards the camera: (0.5, 0, -1)/|.|.
    const Float3 expected{static_cast<float>(0.5 / std::sqrt(1.25)), 0.f, static_cast<float>(-1 / std::sqrt(1.25))};
    for (int r = 0; r < k.height; ++r) {
      for (int c = 0; c < k.width; ++c) {
        ASSERT_GT(dot(normals(r, c), expected), 0.99999f) << "stride " << stride << " at " << r << "," << c;
      }
    }
  }
}

TEST(NormalsFromPositions, DiscontinuitiesAndHolesUseTheOtherSideOrNothing) {
  const PinholeIntrinsics k = small_camera();
  DepthMap depth(k.width, k.height, 2.f);
  for (int r = 0; r < k.height; ++r) {
    for (int c = 40; c < k.width; ++c) depth(r, c) = 1.f;  // a step of 1 m at column 40
  }
  depth(30, 10) = 0.f;
  PositionMap positions;
  positions_from_depth(depth, k, positions);
  NormalMap normals;
  normals_from_positions(positions, normals, {.stride = 1});
  // Column 39's forward neighbour is across the step: the backward difference keeps the plane normal.
  EXPECT_NEAR(normals(20, 39).z, -1.f, 1e-5f);
  EXPECT_NEAR(normals(20, 40).z, -1.f, 1e-5f);
  EXPECT_FALSE(is_valid_normal(normals(30, 10)));  // no depth, no normal
  EXPECT_NEAR(normals(30, 9).z, -1.f, 1e-5f);      // neighbour of a hole: backward difference
}

// The forward differences of eq. 4.4–4.5 describe the surface half a stride away from the pixel;
// on the scene's curved objects that tilts their normals even on exact depth. Central differences
// over the same stride do not, and on noisy depth their doubled baseline halves the noise.
TEST(NormalsFromPositions, CentralDifferencesRemoveTheHalfStrideTilt) {
  const auto sequence = test::render_sequence(synth::Trajectory::Static, 1);
  const auto& frame = sequence.frames.front();
  // Curved surfaces: no depth step within the stencil, and not flat.
  Mask curved = continuous_depth_mask(frame.true_depth, 4);
  const Mask flat = flat_region_mask(frame.true_normals, 4, 1.0);
  for (std::size_t i = 0; i < curved.size(); ++i) curved.pixels()[i] = curved.pixels()[i] && !flat.pixels()[i];
  const auto error = [&](const DepthMap& depth, bool centred, const Mask* region) {
    PositionMap positions;
    NormalMap normals;
    positions_from_depth(depth, sequence.intrinsics, positions);
    normals_from_positions(positions, normals, {.stride = 4, .centred = centred});
    const AngularError e = angular_error(normals, frame.true_normals, region);
    EXPECT_GT(e.compared, 2000u);  // the scene has curved objects
    return e.mean_deg;
  };
  const double exact_forward = error(frame.true_depth, false, &curved);
  const double exact_centred = error(frame.true_depth, true, &curved);
  const double noisy_forward = error(frame.noisy, false, nullptr), noisy_centred = error(frame.noisy, true, nullptr);
  std::printf("stride 4, exact depth on curved surfaces: forward %.2f deg, central %.2f deg; noisy depth, all "
              "pixels: %.2f, %.2f deg\n",
              exact_forward, exact_centred, noisy_forward, noisy_centred);
  EXPECT_LT(exact_centred, 0.6 * exact_forward);  // measured 3.90 vs 7.58
  EXPECT_LT(noisy_centred, 0.75 * noisy_forward);  // measured 16.72 vs 26.74
}

// Mean angular error over the valid pixels of the last frame of a static-camera sequence.
struct Method1Errors {
  AngularError raw, stride4, filtered;
};

Method1Errors run_method1(const test::SyntheticSequence& sequence, const NormalsRawDepthOptions& options = {}) {
  PositionMap positions[2];
  NormalMap normals[2];
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const auto& frame = sequence.frames[i];
    const std::size_t cur = i % 2, prev = 1 - cur;
    const NormalsHistory history{normals[prev], positions[prev], i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity()};
    normals_raw_depth(frame.noisy, sequence.intrinsics, frame.camera_to_world, i > 0 ? &history : nullptr, options,
                      positions[cur], normals[cur]);
  }
  const auto& last = sequence.frames.back();
  const NormalMap& filtered = normals[(sequence.frames.size() - 1) % 2];
  Method1Errors errors;
  PositionMap raw_positions;
  positions_from_depth(last.noisy, sequence.intrinsics, raw_positions);
  NormalMap raw;
  normals_from_positions(raw_positions, raw, {.stride = 1});
  errors.raw = angular_error(raw, last.true_normals);
  NormalMap single;
  normals_raw_depth(last.noisy, sequence.intrinsics, last.camera_to_world, nullptr, options, raw_positions, single);
  errors.stride4 = angular_error(single, last.true_normals);
  errors.filtered = angular_error(filtered, last.true_normals);
  return errors;
}

TEST(NormalsRawDepth, StaticCameraTenFramesIsFarBetterThanRawNormals) {
  const auto sequence = test::render_sequence(synth::Trajectory::Static, 10);
  const Method1Errors e = run_method1(sequence);
  std::printf("static: raw %.2f deg, method 1 one frame %.2f deg, method 1 ten frames %.2f deg (coverage %.3f)\n",
              e.raw.mean_deg, e.stride4.mean_deg, e.filtered.mean_deg, e.filtered.coverage);
  EXPECT_LT(e.filtered.mean_deg, 0.5 * e.raw.mean_deg);
  EXPECT_LT(e.filtered.mean_deg, e.stride4.mean_deg);  // the temporal filter helps beyond the stride
  EXPECT_GE(e.filtered.coverage, e.raw.coverage);      // hole filling: no pixel lost to the stride
}

TEST(NormalsRawDepth, LongerHistoryDriftsLittleWithTheDefaultMipChain) {
  // The blend re-smooths the history every frame through the mip level that the curvature
  // picks; coarse levels average curved surfaces away, so the error grows with the frame count.
  // Measured (320x240, 10 -> 40 static frames): 2 levels (the default) 5.41 -> 5.54 deg, 4
  // levels (down to 16 x 16 pixels) 7.71 -> 8.98. Before the level-0 texels stood for their
  // whole 2x2 block (normals_raw_depth.h), the history drifted half a pixel per frame: 2 levels
  // 7.32 -> 8.15 (forward differences), 6.27 -> 7.31 (central ones).
  const auto sequence = test::render_sequence(synth::Trajectory::Static, 40);
  test::SyntheticSequence first_ten = sequence;
  first_ten.frames.resize(10);
  const auto errors = [&](int levels) {
    const NormalsRawDepthOptions options{.mip_levels = levels};
    return std::pair{run_method1(first_ten, options).filtered.mean_deg, run_method1(sequence, options).filtered.mean_deg};
  };
  const auto [ten, forty] = errors(NormalsRawDepthOptions{}.mip_levels);
  const auto [ten_deep, forty_deep] = errors(4);
  std::printf("static, default mip chain: 10 frames %.2f deg, 40 frames %.2f deg; 4 levels %.2f, %.2f deg\n", ten,
              forty, ten_deep, forty_deep);
  EXPECT_LT(forty, 1.1 * ten);
  EXPECT_LT(forty, forty_deep);
}

TEST(NormalsRawDepth, OrbitWithPosesStaysBetterThanRaw) {
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 8);
  const Method1Errors e = run_method1(sequence);
  std::printf("orbit: raw %.2f deg, method 1 one frame %.2f deg, method 1 eight frames %.2f deg\n", e.raw.mean_deg,
              e.stride4.mean_deg, e.filtered.mean_deg);
  EXPECT_LT(e.filtered.mean_deg, 0.5 * e.raw.mean_deg);
  EXPECT_LT(e.filtered.mean_deg, e.stride4.mean_deg);
}

TEST(NormalsRawDepth, IgnoringThePoseOnAnOrbitIsWorseThanUsingIt) {
  // The pose change must be applied: feeding identity poses blends normals of the wrong pixels
  // and the wrong camera frame.
  // Every 6th orbit frame: 4 degrees of rotation per frame.
  auto sequence = test::render_sequence(synth::Trajectory::Orbit, 8, 320, 240, {}, 6);
  const double with_pose = run_method1(sequence).filtered.mean_deg;
  const Pose first = sequence.frames.front().camera_to_world;
  for (auto& frame : sequence.frames) frame.camera_to_world = first;
  const double without_pose = run_method1(sequence).filtered.mean_deg;
  std::printf("orbit: with poses %.2f deg, poses ignored %.2f deg\n", with_pose, without_pose);
  EXPECT_LT(with_pose, without_pose);
}

TEST(NormalsRawDepth, FirstFrameIsStrideFourNormalsWithHolesFilled) {
  const PinholeIntrinsics k = small_camera();
  DepthMap depth = tilted_plane(k, 1.5, -0.3);
  depth(20, 20) = 0.f;
  PositionMap positions;
  NormalMap normals;
  normals_raw_depth(depth, k, Pose::Identity(), nullptr, {}, positions, normals);
  const Float3 expected{static_cast<float>(-0.3 / std::sqrt(1.09)), 0.f, static_cast<float>(-1 / std::sqrt(1.09))};
  for (int r = 0; r < k.height; ++r) {
    for (int c = 0; c < k.width; ++c) {
      if (r == 20 && c == 20) {
        EXPECT_FALSE(is_valid_normal(normals(r, c)));
        continue;
      }
      ASSERT_GT(dot(normals(r, c), expected), 0.99999f) << r << "," << c;
    }
  }
}

TEST(NormalsRawDepth, DisocclusionResetsTheHistory) {
  // Previous frame: a plane at 2 m with normals deliberately wrong; current: a plane at 1 m.
  // The depth change (1 m > 0.1 m) must discard the history, so the result is the fresh normal.
  const PinholeIntrinsics k = small_camera();
  const DepthMap near = tilted_plane(k, 1.0, 0.0);
  PositionMap previous_positions;
  positions_from_depth(tilted_plane(k, 2.0, 0.0), k, previous_positions);
  const float s = static_cast<float>(std::sqrt(0.5));
  const NormalMap previous_normals(k.width, k.height, Float3{s, 0.f, -s});
  const NormalsHistory history{previous_normals, previous_positions, Pose::Identity()};
  PositionMap positions;
  NormalMap normals;
  normals_raw_depth(near, k, Pose::Identity(), &history, {}, positions, normals);
  EXPECT_NEAR(normals(30, 40).z, -1.f, 1e-5f);
  // Same depth in both frames: now the history counts (c >= c_B = 0.9), the normal tilts towards it.
  const NormalsHistory same_depth{previous_normals, positions, Pose::Identity()};
  NormalMap blended;
  PositionMap unused;
  normals_raw_depth(near, k, Pose::Identity(), &same_depth, {}, unused, blended);
  EXPECT_GT(blended(30, 40).x, 0.5f);
}

// ---- The CPU loops: AVX2 and scalar, fused and composed -----------------------------------

struct Method1Outputs {
  std::vector<PositionMap> positions;
  std::vector<NormalMap> normals;
};

// Method 1 over a whole sequence with one NormalsRawDepthCpu (scratch memory reused).
Method1Outputs run_frames(const test::SyntheticSequence& sequence, const NormalsRawDepthOptions& options) {
  NormalsRawDepthCpu method;
  Method1Outputs out;
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const auto& frame = sequence.frames[i];
    out.positions.emplace_back();
    out.normals.emplace_back();
    std::optional<NormalsHistory> history;
    if (i > 0) history.emplace(NormalsHistory{out.normals[i - 1], out.positions[i - 1], sequence.frames[i - 1].camera_to_world});
    method.run(frame.noisy, sequence.intrinsics, frame.camera_to_world, history ? &*history : nullptr, options,
               out.positions.back(), out.normals.back());
  }
  return out;
}

std::size_t valid_normals(const NormalMap& normals) {
  return static_cast<std::size_t>(std::count_if(normals.pixels().begin(), normals.pixels().end(), is_valid_normal));
}

TEST(NormalsRawDepthCpu, AvxLoopsEqualScalarLoopsBitForBit) {
  if (!normals_raw_depth_simd_available()) GTEST_SKIP() << "this CPU has no AVX2: only the scalar loops run";
  // 203x151: rows that are not a multiple of 8 pixels and pyramid levels with odd sides. Every
  // 6th orbit pose: reprojected neighbours are not always neighbours (the gather path) while
  // most are (the coherent path).
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 4, 203, 151, {}, 6);
  const std::vector<NormalsRawDepthOptions> variants{{}, {.stride = 1}, {.mip_levels = 1}, {.mip_levels = 7}};
  for (const NormalsRawDepthOptions& variant : variants) {
    NormalsRawDepthOptions scalar = variant;
    scalar.simd = false;
    const Method1Outputs a = run_frames(sequence, variant);
    const Method1Outputs b = run_frames(sequence, scalar);
    for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
      EXPECT_TRUE(a.positions[i] == b.positions[i]) << "frame " << i << ", stride " << variant.stride;
      EXPECT_TRUE(a.normals[i] == b.normals[i]) << "frame " << i << ", stride " << variant.stride << ", levels "
                                                << variant.mip_levels;
      EXPECT_GT(valid_normals(a.normals[i]), a.normals[i].size() / 2);  // not an empty comparison
    }
  }
}

// The fused pass (positions, cross products and blend per row) equals its definition: the
// positions_from_depth + normals_from_positions reference, then normals_raw_depth_blend; on both
// the AVX2 and the scalar loops. Exact equality holds because both evaluate the same float
// operations in the same order (no fused multiply-add on x86-64, see normals_raw_depth_kernels.h).
TEST(NormalsRawDepthCpu, FusedPassEqualsReferenceCrossProductsThenBlend) {
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 3, 160, 120, {}, 3);
  for (const bool simd : {true, false}) {
    const NormalsRawDepthOptions options{.simd = simd};
    const Method1Outputs fused = run_frames(sequence, options);
    PositionMap positions[2];
    NormalMap normals[2];
    for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
      const auto& frame = sequence.frames[i];
      const std::size_t cur = i % 2, prev = 1 - cur;
      positions_from_depth(frame.noisy, sequence.intrinsics, positions[cur]);
      normals_from_positions(positions[cur], normals[cur], cross_normal_options(options));
      const NormalsHistory history{normals[prev], positions[prev], i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity()};
      normals_raw_depth_blend(sequence.intrinsics, frame.camera_to_world, i > 0 ? &history : nullptr, options,
                              positions[cur], normals[cur]);
      EXPECT_TRUE(fused.positions[i] == positions[cur]) << "frame " << i << (simd ? " simd" : " scalar");
      EXPECT_TRUE(fused.normals[i] == normals[cur]) << "frame " << i << (simd ? " simd" : " scalar");
    }
  }
}

// Hole filling as defined: every hole (a position without a normal) takes the normalised sum of
// its 4-neighbours in the map before any fill; transcribed here on a frame with many holes next
// to holes (scattered missing depth), at sizes that split the rows over several tasks.
TEST(NormalsRawDepthCpu, HolesAreFilledFromTheUnfilledNeighbours) {
  auto sequence = test::render_sequence(synth::Trajectory::Static, 1, 160, 120);
  DepthMap depth = sequence.frames[0].noisy;
  for (int r = 0; r < depth.height(); ++r) {
    for (int c = 0; c < depth.width(); ++c) {
      if ((r * 31 + c * 17) % 13 == 0 || (r % 9 == 4 && c % 11 < 5)) depth(r, c) = 0.f;
    }
  }
  PositionMap positions;
  NormalMap expected;
  positions_from_depth(depth, sequence.intrinsics, positions);
  normals_from_positions(positions, expected, cross_normal_options({}));
  const NormalMap unfilled = expected;
  int holes = 0, holes_next_to_holes = 0;
  const auto hole = [&](int r, int c) {
    return unfilled.in_bounds(r, c) && positions(r, c).z > 0.f && !is_valid_normal(unfilled(r, c));
  };
  for (int r = 0; r < depth.height(); ++r) {
    for (int c = 0; c < depth.width(); ++c) {
      if (!hole(r, c)) continue;
      ++holes;
      holes_next_to_holes += hole(r - 1, c) || hole(r + 1, c) || hole(r, c - 1) || hole(r, c + 1) ? 1 : 0;
      Float3 sum;
      for (const auto& [dr, dc] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
        if (unfilled.in_bounds(r + dr, c + dc)) sum += unfilled(r + dr, c + dc);
      }
      const Float3 n = length(sum) > 0.f ? (1.f / length(sum)) * sum : Float3{};
      if (is_valid_normal(n)) expected(r, c) = n;
    }
  }
  EXPECT_GT(holes, 200);
  EXPECT_GT(holes_next_to_holes, 20);
  for (const bool simd : {true, false}) {
    for (const int threads : {1, 2, 3}) {
      PositionMap got_positions;
      NormalMap got;
      normals_raw_depth(depth, sequence.intrinsics, Pose::Identity(), nullptr, {.threads = threads, .simd = simd},
                        got_positions, got);
      EXPECT_TRUE(got == expected) << "threads " << threads << (simd ? " simd" : " scalar");
    }
  }
}

TEST(NormalsRawDepthCpu, OneObjectOverFramesOfDifferentSizesEqualsFreshCalls) {
  const auto large = test::render_sequence(synth::Trajectory::Orbit, 2, 160, 120);
  const auto small = test::render_sequence(synth::Trajectory::Orbit, 2, 72, 50);
  NormalsRawDepthCpu method;
  for (const auto* sequence : {&large, &small, &large}) {
    PositionMap positions[2], fresh_positions[2];
    NormalMap normals[2], fresh_normals[2];
    for (std::size_t i = 0; i < 2; ++i) {
      const auto& frame = sequence->frames[i];
      const NormalsHistory history{normals[1 - i], positions[1 - i], sequence->frames[0].camera_to_world};
      const NormalsHistory fresh_history{fresh_normals[1 - i], fresh_positions[1 - i], sequence->frames[0].camera_to_world};
      method.run(frame.noisy, sequence->intrinsics, frame.camera_to_world, i > 0 ? &history : nullptr, {}, positions[i],
                 normals[i]);
      normals_raw_depth(frame.noisy, sequence->intrinsics, frame.camera_to_world, i > 0 ? &fresh_history : nullptr, {},
                        fresh_positions[i], fresh_normals[i]);
      EXPECT_TRUE(normals[i] == fresh_normals[i]) << sequence->intrinsics.width << " frame " << i;
      EXPECT_TRUE(positions[i] == fresh_positions[i]);
    }
  }
}

// Pass 1 (eq. 4.1–4.3) against a direct transcription of its definition on a curved, noisy
// normal map with holes, wide enough for the AVX2 loops (75 columns: odd, so the last texel's
// block lies half outside the image).
TEST(NormalsHistoryPyramid, MatchesTheDefinitionOfPassOne) {
  const int width = 75, height = 42;
  NormalMap previous(width, height);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      if ((r * 7 + c * 3) % 23 == 0) continue;  // holes
      const float bumps = c > 40 ? 0.3f * std::sin(0.5f * static_cast<float>(r * c)) : 0.f;  // curved right half
      const float a = 0.04f * static_cast<float>(c) + bumps;
      const float b = 0.03f * static_cast<float>(r);
      const Float3 n{std::sin(a), std::sin(b), -std::cos(a) * std::cos(b)};
      previous(r, c) = (1.f / length(n)) * n;
    }
  }
  const auto pyramid = normals_history_pyramid(previous, 4);
  ASSERT_EQ(pyramid.size(), 4u);
  const auto at = [&](int r, int c) { return previous.in_bounds(r, c) ? previous(r, c) : Float3{}; };
  const auto normalised = [](const Float3& v) { return length(v) > 0.f ? (1.f / length(v)) * v : Float3{}; };
  ASSERT_EQ(pyramid[0].normal.width(), 38);
  ASSERT_EQ(pyramid[0].normal.height(), 21);
  int flat = 0;
  for (int hr = 0; hr < 21; ++hr) {
    for (int hc = 0; hc < 38; ++hc) {
      const int r = 2 * hr, c = 2 * hc;
      const Float3 up = at(r - 1, c), down = at(r + 1, c), left = at(r, c - 1), right = at(r, c + 1);
      // The texel stands for its 2x2 block: the 4-neighbourhood sums of the block's pixels.
      Float3 sum;
      for (const auto& [br, bc] : {std::pair{r, c}, std::pair{r, c + 1}, std::pair{r + 1, c}, std::pair{r + 1, c + 1}})
        sum += at(br, bc) + at(br - 1, bc) + at(br + 1, bc) + at(br, bc - 1) + at(br, bc + 1);
      const Float3 mean = normalised(sum);
      float curvature = 0.f;
      if (is_valid_normal(up) && is_valid_normal(down) && is_valid_normal(left) && is_valid_normal(right)) {
        curvature = std::pow(std::clamp(std::min(dot(left, right), dot(up, down)), 0.f, 1.f), 128.f);
      }
      flat += curvature > 0.5f ? 1 : 0;
      const Float3& got = pyramid[0].normal(hr, hc);
      ASSERT_NEAR(got.x, mean.x, 1e-6f) << hr << "," << hc;
      ASSERT_NEAR(got.y, mean.y, 1e-6f);
      ASSERT_NEAR(got.z, mean.z, 1e-6f);
      ASSERT_NEAR(pyramid[0].curvature(hr, hc), curvature, 1e-4f) << hr << "," << hc;
    }
  }
  EXPECT_GT(flat, 100);  // both smooth and curved texels occur
  EXPECT_LT(flat, 38 * 21 - 100);
  for (std::size_t level = 1; level < pyramid.size(); ++level) {
    const auto& fine = pyramid[level - 1];
    const auto& coarse = pyramid[level];
    ASSERT_EQ(coarse.normal.width(), (fine.normal.width() + 1) / 2);
    for (int r = 0; r < coarse.normal.height(); ++r) {
      for (int c = 0; c < coarse.normal.width(); ++c) {
        Float3 sum;
        float curvature = 0.f;
        int count = 0;
        for (int dr = 0; dr < 2; ++dr) {
          for (int dc = 0; dc < 2; ++dc) {
            if (!fine.normal.in_bounds(2 * r + dr, 2 * c + dc) || !is_valid_normal(fine.normal(2 * r + dr, 2 * c + dc))) continue;
            sum += fine.normal(2 * r + dr, 2 * c + dc);
            curvature += fine.curvature(2 * r + dr, 2 * c + dc);
            ++count;
          }
        }
        const Float3 mean = normalised(sum);
        ASSERT_NEAR(coarse.normal(r, c).x, mean.x, 1e-6f) << "level " << level;
        ASSERT_NEAR(coarse.normal(r, c).z, mean.z, 1e-6f) << "level " << level;
        ASSERT_NEAR(coarse.curvature(r, c), count ? curvature / static_cast<float>(count) : 0.f, 1e-6f);
      }
    }
  }
}

// ---- Frame graph -------------------------------------------------------------------------

TEST(NormalsRawDepthStage, GraphRunEqualsDirectCallsWithHistory) {
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 3, 160, 120);
  FrameGraph graph;
  graph.emplace<test::SequenceSource>(sequence);
  graph.emplace<NormalsRawDepthCpuStage>();
  graph.keep("normals");
  graph.compile();
  PositionMap positions[2];
  NormalMap normals[2];
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(graph.run_frame());
    const std::size_t cur = i % 2, prev = 1 - cur;
    const NormalsHistory history{normals[prev], positions[prev], i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity()};
    normals_raw_depth(sequence.frames[i].noisy, sequence.intrinsics, sequence.frames[i].camera_to_world,
                      i > 0 ? &history : nullptr, {}, positions[cur], normals[cur]);
    const NormalMap* from_graph = graph.find<NormalMap>("normals");
    ASSERT_NE(from_graph, nullptr);
    EXPECT_TRUE(*from_graph == normals[cur]) << "frame " << i;
  }
}

}  // namespace
}  // namespace relight::reconstruct
