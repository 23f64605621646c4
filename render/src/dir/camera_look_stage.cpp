#include "relight/render/dir/camera_look_stage.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "relight/colormap/buffers.h"
#include "relight/core/buffers.h"
#include "relight/render/buffers.h"

namespace relight::render {

namespace {

constexpr double kLongestFrameInterval = 0.25;  // seconds; beyond it frames were skipped
/// Frames that measure both the blur and the noise before they alternate (the running estimates
/// start from one frame's; averaging a few first keeps a short sequence's as good as before).
constexpr int kFramesBeforeAlternating = 8;

double blend(double previous, double current, double weight) { return previous + weight * (current - previous); }

}  // namespace

colormap::MotionField image_motion(const GBuffer& gbuffer, const FrameInfo& frame, const FrameInfo& previous,
                                   double exposure_time_s, int cell) {
  colormap::MotionField field;
  field.cell = cell;
  const double interval = frame.timestamp - previous.timestamp;
  if (!frame.camera_to_world || !previous.camera_to_world || !(interval > 0.0) || interval > kLongestFrameInterval)
    return field;
  const int width = gbuffer.distance.width(), height = gbuffer.distance.height();
  const int columns = (width + cell - 1) / cell, rows = (height + cell - 1) / cell;
  if (columns == 0 || rows == 0) return field;
  const PinholeIntrinsics& k = frame.intrinsics;
  const Pose world_to_previous = previous.camera_to_world->inverse();
  const Pose& camera_to_world = *frame.camera_to_world;
  // Depth where the G-buffer sees nothing: the median of the cells that see something.
  std::vector<double> depths;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      const float d =
          gbuffer.distance(std::min(height - 1, r * cell + cell / 2), std::min(width - 1, c * cell + cell / 2));
      if (d > 0.f) depths.push_back(d);
    }
  double fallback = 2.0;
  if (!depths.empty()) {
    std::nth_element(depths.begin(), depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2), depths.end());
    fallback = depths[depths.size() / 2];
  }
  const double scale = std::min(1.0, exposure_time_s / interval);
  field.motion = Image<Float3>(columns, rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      // The cell's centre; pixel (row, col)'s centre is at (col, row), as k.ray has it.
      const double u = (c + 0.5) * cell - 0.5, v = (r + 0.5) * cell - 0.5;
      const int pr = std::min(height - 1, static_cast<int>(std::lround(v)));
      const int pc = std::min(width - 1, static_cast<int>(std::lround(u)));
      const float seen = gbuffer.distance(pr, pc);
      // The G-buffer's distance is along the ray, from the camera centre.
      const Eigen::Vector3d ray = k.ray(u, v).normalized();
      const Eigen::Vector3d world = camera_to_world * (ray * (seen > 0.f ? double(seen) : fallback));
      const Eigen::Vector3d in_previous = world_to_previous * world;
      if (in_previous.z() <= 1e-3) continue;
      const Eigen::Vector2d before = k.project(in_previous);
      Eigen::Vector2d moved = scale * (Eigen::Vector2d(u, v) - before);
      if (!moved.allFinite()) continue;
      if (moved.norm() > colormap::kMaxMotionPx) moved *= colormap::kMaxMotionPx / moved.norm();
      field.motion(r, c) = {float(moved.x()), float(moved.y()), 0.f};
    }
  }
  return field;
}

void CameraLookStage::declare(StageBuilder& builder) {
  color_ = builder.read(kColor);
  frame_ = builder.read(kFrame);
  previous_frame_ = builder.read_previous(kFrame);
  gbuffer_ = builder.read(kDirGBuffer);
  previous_look_ = builder.read_previous(colormap::kCameraLook);
  look_ = builder.write(colormap::kCameraLook);
}

void CameraLookStage::run(StageContext& context) {
  const ColorImage& color = context.get(color_);
  const FrameInfo& frame = context.get(frame_);
  const FrameInfo* previous_frame = context.get(previous_frame_);
  const colormap::CameraLook* previous = context.get(previous_look_);
  colormap::CameraLook& look = context.get(look_);
  look = colormap::CameraLook{};
  look.artefacts = options_.artefacts;
  look.seed = static_cast<std::uint64_t>(frame.index) * 0x9e3779b97f4a7c15ULL + 1;
  if (previous_frame)
    look.motion = image_motion(context.get(gbuffer_), frame, *previous_frame, options_.exposure_time_s);

  // Which estimates this frame makes: both while the running estimates settle, then alternating.
  const bool both_known =
      previous && previous->blur.valid() && previous->noise.valid() && summary_.frames >= kFramesBeforeAlternating;
  const bool alternate =
      options_.alternate_estimates && options_.artefacts.blur && options_.artefacts.noise && both_known;
  const bool measure_blur = !alternate || summary_.frames % 2 == 0;
  const bool measure_noise = !alternate || summary_.frames % 2 == 1;
  if (options_.artefacts.blur && !measure_blur) {
    look.blur = previous->blur;
    look.blur_sigma_px = previous->blur_sigma_px;
  } else if (options_.artefacts.blur) {
    // Edges along the motion only: the mean motion's direction (camera motion moves the image
    // nearly uniformly; rotation does exactly).
    std::optional<Eigen::Vector2f> direction;
    if (!look.motion.empty()) {
      Eigen::Vector2f mean = Eigen::Vector2f::Zero();
      for (const Float3& m : look.motion.motion.pixels()) mean += Eigen::Vector2f(m.x, m.y);
      mean /= float(look.motion.motion.size());
      if (mean.norm() > 0.5f) direction = mean;
    }
    look.blur = colormap::estimate_camera_blur(color, options_.blur, direction);
    ++summary_.blur_estimates;
    if (previous && previous->blur.valid()) {
      if (look.blur.valid())
        look.blur.sigma_px = blend(previous->blur.sigma_px, look.blur.sigma_px, options_.smoothing);
      else
        look.blur = previous->blur;
    }
    const double variance = look.blur.sigma_px * look.blur.sigma_px - options_.render_variance_px2;
    look.blur_sigma_px = static_cast<float>(std::sqrt(std::max(0.0, variance)));
  }
  ++summary_.frames;
  summary_.blur_sigma_px = look.blur.sigma_px;
  summary_.applied_sigma_px = look.blur_sigma_px;
  summary_.blur_edges = look.blur.edges;
  if (!look.motion.empty()) {
    ++summary_.frames_with_motion;
    summary_.max_motion_px = std::max(summary_.max_motion_px, double(look.motion.max_length()));
  }
  if (options_.artefacts.noise && !measure_noise) {
    look.noise = previous->noise;
    summary_.noise = look.noise;
  } else if (options_.artefacts.noise) {
    look.noise = colormap::estimate_camera_noise(color, options_.noise);
    ++summary_.noise_estimates;
    if (previous && previous->noise.valid()) {
      if (!look.noise.valid()) {
        look.noise = previous->noise;
      } else {
        for (std::size_t band = 0; band < look.noise.sigma.size(); ++band)
          for (std::size_t ch = 0; ch < 3; ++ch)
            look.noise.sigma[band][ch] = static_cast<float>(
                blend(previous->noise.sigma[band][ch], look.noise.sigma[band][ch], options_.smoothing));
      }
    }
    summary_.noise = look.noise;
  }
}

}  // namespace relight::render
