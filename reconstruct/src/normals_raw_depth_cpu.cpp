// CPU implementation of method 1 (definition in normals_raw_depth.h). Per frame: pass 1 builds
// the pyramid from the previous normals (rows in parallel, two level-0 rows and one level-1 row
// per task, coarser levels after), pass 2 computes positions, cross products and the blend per
// row in parallel and lists each row's holes, and the holes are filled last (few pixels, one
// thread). The per-pixel work is in normals_raw_depth_kernels.h (scalar) and
// normals_raw_depth_avx2.cpp (AVX2, same results).
#include <algorithm>
#include <cmath>
#include <vector>

#include "normals_raw_depth_kernels.h"
#include "relight/core/buffers.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/reconstruct/normals_raw_depth.h"

namespace relight::reconstruct {

namespace method1 {
/// What NormalsRawDepthCpu keeps between frames.
struct Scratch {
  std::vector<LevelShape> shapes;  ///< of the pyramid levels (each block's pyramid lives in its thread)
  History history;
  std::vector<float> x_scale;               ///< padded by stride + 8 on both sides
  std::vector<std::uint32_t> hole_columns;  ///< row r's holes at r * width
  std::vector<Float3> hole_values;          ///< same indexing
  std::vector<int> hole_counts;
  std::vector<std::uint32_t> hole_bits;
  std::vector<std::uint8_t> filled;         ///< per row: holes filled inside the row pass
};
}  // namespace method1

struct NormalsRawDepthCpu::Workspace : method1::Scratch {};

namespace {

using method1::Pyramid;

bool use_avx2(const NormalsRawDepthOptions& options) { return options.simd && method1::avx2_available(); }

// Level shapes as the reference pyramid: half resolution (rounding up), halving while both sides
// exceed one texel, at most `levels` levels; offsets as if all rows were stored.
void shape_levels(std::vector<method1::LevelShape>& shapes, int width, int height, int levels) {
  shapes.clear();
  int w = (width + 1) / 2, h = (height + 1) / 2, size = w * h;
  shapes.push_back({w, h, 0});
  while (static_cast<int>(shapes.size()) < std::max(1, levels) && w > 1 && h > 1) {
    w = (w + 1) / 2;
    h = (h + 1) / 2;
    shapes.push_back({w, h, size});
    size += w * h;
  }
}

// Storage for `shapes` with `rows(l)` rows at level l, plus 8 padding elements: the AVX2 loops
// load eight neighbouring texels from any texel on.
template <class Rows>
void allocate(Pyramid& pyramid, const std::vector<method1::LevelShape>& shapes, Rows rows) {
  pyramid.levels.clear();
  int size = 0;
  for (std::size_t l = 0; l < shapes.size(); ++l) {
    pyramid.levels.push_back({shapes[l].width, rows(static_cast<int>(l)), size});
    size += shapes[l].width * rows(static_cast<int>(l));
  }
  for (auto* v : {&pyramid.x, &pyramid.y, &pyramid.z, &pyramid.curvature}) v->resize(static_cast<std::size_t>(size) + 8);
}

void level0_row(const NormalMap& previous, int hr, Pyramid& out, int out_row, bool avx2) {
  if (avx2) {
    method1::level0_row_avx2(previous.data(), previous.width(), previous.height(), hr, out, out_row);
    return;
  }
  for (int hc = 0; hc < out.levels[0].width; ++hc) {
    method1::level0_texel(previous.data(), previous.width(), previous.height(), hr, hc, out, out_row);
  }
}

void coarse_row(Pyramid& pyramid, int level, int r, bool avx2) {
  if (avx2) {
    method1::coarse_row_avx2(pyramid, level, r);
    return;
  }
  for (int c = 0; c < pyramid.levels[static_cast<std::size_t>(level)].width; ++c) {
    method1::coarse_texel(pyramid, level, r, c);
  }
}

void resolve_row(const Pyramid& pyramid, const method1::Constants& k, int r, method1::History& out, int out_row,
                 bool avx2) {
  if (avx2) {
    method1::resolve_row_avx2(pyramid, k, r, out, out_row);
    return;
  }
  for (int c = 0; c < pyramid.levels[0].width; ++c) method1::resolve_texel(pyramid, k, r, c, out, out_row);
}

// Pass 1 runs in blocks of 2^(levels − 1) level-0 rows: level l's rows above a block come from
// that block's rows only, so one task builds every level of its block while it is in its cache.
int block_rows(const std::vector<method1::LevelShape>& shapes) { return 1 << (static_cast<int>(shapes.size()) - 1); }

// Block b's rows of every level into `out`, whose row 0 of level l is global row first(l).
template <class First>
void build_block(const NormalMap& previous, const std::vector<method1::LevelShape>& shapes, int b, Pyramid& out,
                 First first, bool avx2) {
  const int block = block_rows(shapes);
  for (int level = 0; level < static_cast<int>(shapes.size()); ++level) {
    const int rows = block >> level;
    const int end = std::min((b + 1) * rows, shapes[static_cast<std::size_t>(level)].height);
    for (int r = b * rows; r < end; ++r) {
      if (level == 0) {
        level0_row(previous, r, out, r - first(0), avx2);
      } else {
        coarse_row(out, level, r - first(level), avx2);
      }
    }
  }
}

// The whole pyramid (normals_history_pyramid).
void build_pyramid(const NormalMap& previous, int levels, int threads, bool avx2, Pyramid& pyramid) {
  std::vector<method1::LevelShape> shapes;
  shape_levels(shapes, previous.width(), previous.height(), levels);
  allocate(pyramid, shapes, [&](int l) { return shapes[static_cast<std::size_t>(l)].height; });
  const int block = block_rows(shapes);
  parallel_for_each_row(
      (shapes[0].height + block - 1) / block, threads,
      [&](int b) { build_block(previous, shapes, b, pyramid, [](int) { return 0; }, avx2); }, 1);
}

// Pass 1 for pass 2: each block's pyramid in a scratch of the task's thread (it never leaves the
// cache), resolved into `history`.
void build_history(const NormalMap& previous, const method1::Constants& k, int levels, int threads, bool avx2,
                   std::vector<method1::LevelShape>& shapes, method1::History& history) {
  shape_levels(shapes, previous.width(), previous.height(), levels);
  history.width = shapes[0].width;
  const auto texels = static_cast<std::size_t>(shapes[0].width) * static_cast<std::size_t>(shapes[0].height) + 8;
  for (auto* v : {&history.x, &history.y, &history.z}) v->resize(texels);
  const int block = block_rows(shapes);
  parallel_for_each_row(
      (shapes[0].height + block - 1) / block, threads,
      [&](int b) {
        thread_local Pyramid scratch;
        const auto first = [&](int l) { return b * (block >> l); };
        allocate(scratch, shapes, [&](int l) {
          return std::min(block >> l, shapes[static_cast<std::size_t>(l)].height - first(l));
        });
        build_block(previous, shapes, b, scratch, first, avx2);
        for (int r = 0; r < scratch.levels[0].height; ++r) resolve_row(scratch, k, r, history, first(0) + r, avx2);
      },
      1);
}

}  // namespace

CrossNormalOptions cross_normal_options(const NormalsRawDepthOptions& options) {
  return {.stride = options.stride,
          .max_jump_rel = options.max_jump_rel,
          .centred = options.centred_differences,
          .threads = options.threads};
}

namespace {

method1::Constants frame_constants(const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                                   const NormalsHistory* previous, const NormalsRawDepthOptions& options, int width,
                                   int height) {
  method1::Constants k;
  k.width = width;
  k.height = height;
  k.stride = options.stride;
  k.inv_fx = static_cast<float>(1.0 / intrinsics.fx);
  k.inv_fy = static_cast<float>(1.0 / intrinsics.fy);
  k.cx = static_cast<float>(intrinsics.cx);
  k.cy = static_cast<float>(intrinsics.cy);
  k.fx = static_cast<float>(intrinsics.fx);
  k.fy = static_cast<float>(intrinsics.fy);
  k.max_jump_rel = options.max_jump_rel;
  k.centred = options.centred_differences;
  k.blend_base = options.blend_base;
  k.disocclusion_m = options.disocclusion_m;
  if (previous) {
    // T_prev_from_current maps current camera-frame points into the previous camera frame.
    const Pose prev_from_current = previous->camera_to_world.inverse() * camera_to_world;
    const Pose current_from_prev = prev_from_current.inverse();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) k.prev_from_current[r * 4 + c] = static_cast<float>(prev_from_current.matrix()(r, c));
      for (int c = 0; c < 3; ++c) k.current_from_prev[r * 3 + c] = static_cast<float>(current_from_prev.matrix()(r, c));
    }
  }
  return k;
}

// (c − cx)·inv_fx for c in [−pad, width + pad), as positions_from_depth computes it; returns
// the element of column 0. The AVX2 loop loads eight entries from c ± stride on.
const float* column_scales(std::vector<float>& table, const method1::Constants& k) {
  const int pad = std::clamp(k.stride, 0, k.width) + 8;
  table.resize(static_cast<std::size_t>(k.width + 2 * pad));
  for (int i = 0; i < k.width + 2 * pad; ++i) {
    table[static_cast<std::size_t>(i)] = (static_cast<float>(i - pad) - k.cx) * k.inv_fx;
  }
  return table.data() + pad;
}

bool usable(const NormalsHistory* previous, const Image<Float3>& shape) {
  return previous && previous->normals.same_shape(shape) && previous->positions.same_shape(shape);
}

// Pass 1 (when there is history) and everything pass 2 needs except its image pointers.
method1::Pass2 prepare(method1::Scratch& ws, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                       const NormalsHistory* previous, const NormalsRawDepthOptions& options, int width, int height) {
  method1::Pass2 pass;
  pass.k = frame_constants(intrinsics, camera_to_world, previous, options, width, height);
  if (previous) {
    build_history(previous->normals, pass.k, options.mip_levels, options.threads, use_avx2(options), ws.shapes,
                  ws.history);
    pass.prev_positions = previous->positions.data();
    pass.history = &ws.history;
  }
  // Sized for the worst case but touched only where there are holes.
  const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (ws.hole_columns.size() < pixels) ws.hole_columns.resize(pixels);
  if (ws.hole_values.size() < pixels) ws.hole_values.resize(pixels);
  pass.hole_words = (width + 31) / 32;
  ws.hole_bits.resize(static_cast<std::size_t>(pass.hole_words) * static_cast<std::size_t>(height));
  ws.hole_counts.resize(static_cast<std::size_t>(height));
  ws.filled.resize(static_cast<std::size_t>(height));
  pass.hole_columns = ws.hole_columns.data();
  pass.hole_values = ws.hole_values.data();
  pass.hole_bits = ws.hole_bits.data();
  pass.hole_counts = ws.hole_counts.data();
  return pass;
}

// Pass 2 over the rows in parallel. Each task fills the holes of its rows one row behind, while
// they are in its cache, except its first and last rows (their outer neighbours belong to other
// tasks), which are filled after all rows are blended.
void finish(method1::Scratch& ws, const method1::Pass2& pass, const NormalsRawDepthOptions& options) {
  // The AVX2 row gathers with 32-bit indices into the previous positions (3 floats a pixel) and
  // reads the column table within stride + 8 of the image.
  const bool avx2 = use_avx2(options) && static_cast<long long>(pass.k.width) * pass.k.height * 3 < (1LL << 31) &&
                    pass.k.stride >= 1 && pass.k.stride <= pass.k.width;
  const int height = pass.k.height;
  const auto fill = [&](int r) {
    method1::fill_row(pass, r);
    ws.filled[static_cast<std::size_t>(r)] = 1;
  };
  std::fill(ws.filled.begin(), ws.filled.end(), std::uint8_t{0});
  parallel_rows(height, options.threads, [&](int begin, int end) {
    const int first_inner = begin == 0 ? 0 : begin + 1;  // rows whose upper neighbour is ours
    for (int r = begin; r < end; ++r) {
      method1::clear_holes(pass, r);
      if (avx2) {
        method1::pass2_row_avx2(pass, r);
      } else {
        for (int c = 0; c < pass.k.width; ++c) method1::pass2_pixel(pass, r, c);
      }
      if (r - 1 >= first_inner) fill(r - 1);
    }
    if (end == height && end - 1 >= first_inner) fill(end - 1);
  });
  for (int r = 0; r < height; ++r) {
    if (!ws.filled[static_cast<std::size_t>(r)]) method1::fill_row(pass, r);
  }
}

}  // namespace

NormalsRawDepthCpu::NormalsRawDepthCpu() : workspace_(std::make_unique<Workspace>()) {}
NormalsRawDepthCpu::~NormalsRawDepthCpu() = default;

void NormalsRawDepthCpu::run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                             const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                             PositionMap& positions, NormalMap& normals) {
  positions.resize(depth.width(), depth.height());
  normals.resize(depth.width(), depth.height());
  if (depth.empty()) return;
  method1::Pass2 pass = prepare(*workspace_, intrinsics, camera_to_world, usable(previous, positions) ? previous : nullptr,
                                options, depth.width(), depth.height());
  pass.depth = depth.data();
  pass.x_scale = column_scales(workspace_->x_scale, pass.k);
  pass.positions_out = positions.data();
  pass.normals = normals.data();
  finish(*workspace_, pass, options);
}

void NormalsRawDepthCpu::blend(const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                               const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                               const PositionMap& positions, NormalMap& normals) {
  if (!normals.same_shape(positions)) throw LogicError("normals_raw_depth_blend: normals and positions differ in shape");
  if (positions.empty()) return;
  method1::Pass2 pass = prepare(*workspace_, intrinsics, camera_to_world, usable(previous, positions) ? previous : nullptr,
                                options, positions.width(), positions.height());
  pass.positions_in = positions.data();
  pass.normals = normals.data();
  finish(*workspace_, pass, options);
}

bool normals_raw_depth_simd_available() { return method1::avx2_available(); }

std::vector<NormalsPyramidLevel> normals_history_pyramid(const NormalMap& previous, int levels, int threads) {
  Pyramid pyramid;
  build_pyramid(previous, levels, threads, method1::avx2_available(), pyramid);
  std::vector<NormalsPyramidLevel> out;
  for (const method1::LevelShape& shape : pyramid.levels) {
    NormalsPyramidLevel level{Image<Float3>(shape.width, shape.height), Image<float>(shape.width, shape.height)};
    for (std::size_t i = 0; i < level.normal.size(); ++i) {
      const std::size_t j = static_cast<std::size_t>(shape.offset) + i;
      level.normal.pixels()[i] = {pyramid.x[j], pyramid.y[j], pyramid.z[j]};
      level.curvature.pixels()[i] = pyramid.curvature[j];
    }
    out.push_back(std::move(level));
  }
  return out;
}

void normals_raw_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                       const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                       PositionMap& positions, NormalMap& normals) {
  NormalsRawDepthCpu().run(depth, intrinsics, camera_to_world, previous, options, positions, normals);
}

void normals_raw_depth_blend(const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                             const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                             const PositionMap& positions, NormalMap& normals) {
  NormalsRawDepthCpu().blend(intrinsics, camera_to_world, previous, options, positions, normals);
}

std::string NormalsRawDepthStageBase::name() const {
  return input_ == NormalsDepthInput::Raw ? "normals_raw_depth" : "normals_filtered_depth";
}

void NormalsRawDepthStageBase::declare(StageBuilder& builder) {
  depth_ = builder.read(input_ == NormalsDepthInput::Raw ? kDepth : kDepthFiltered);
  frame_ = builder.read(kFrame);
  previous_normals_ = builder.read_previous(kNormals);
  previous_positions_ = builder.read_previous(kPositions);
  previous_frame_ = builder.read_previous(kFrame);
  positions_ = builder.write(kPositions);
  normals_ = builder.write(kNormals);
}

Pose NormalsRawDepthStageBase::camera_to_world(StageContext& context) const {
  return context.get(frame_).camera_to_world.value_or(Pose::Identity());
}

Pose NormalsRawDepthStageBase::previous_camera_to_world(StageContext& context) const {
  const FrameInfo* previous_frame = context.get(previous_frame_);
  return previous_frame && previous_frame->camera_to_world ? *previous_frame->camera_to_world : Pose::Identity();
}

void NormalsRawDepthCpuStage::run(StageContext& context) {
  const NormalMap* previous_normals = context.get(previous_normals_);
  const PositionMap* previous_positions = context.get(previous_positions_);
  std::optional<NormalsHistory> history;
  if (previous_normals && previous_positions) {
    history.emplace(NormalsHistory{*previous_normals, *previous_positions, previous_camera_to_world(context)});
  }
  method_.run(context.get(depth_), context.get(frame_).intrinsics, camera_to_world(context),
              history ? &*history : nullptr, options(), context.get(positions_), context.get(normals_));
}

}  // namespace relight::reconstruct
