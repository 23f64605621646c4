// The point-cone search on Vulkan (cone_search_vk.h): points and queries packed into storage
// buffers, one dispatch of one work group per query.
#include "relight/render/vpl/cone_search_vk.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <utility>

#include "relight/core/error.h"
#include "relight/render/vpl/cone_search_shared.h"
#include "relight/shaders/cone_search_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::render {

struct ConeSearchVk::State {
  explicit State(vk::VulkanContext& context)
      : pipeline(context, {.spirv = shaders::cone_search_comp, .storage_buffers = 3,
                           .push_constant_bytes = sizeof(gpu::ConeSearchParams), .max_descriptor_sets = 2}),
        timer(context) {}
  vk::ComputePipeline pipeline;
  vk::GpuTimer timer;
  // Kept across frames and grown with headroom: the point and query counts change every frame.
  std::optional<vk::VulkanBuffer> points, queries, hits;
  std::uint32_t point_count = 0;
  std::optional<double> gpu_ms;
  double untaken_ms = 0.0;  // every search's GPU time since the last take_gpu_ms()
};

ConeSearchVk::ConeSearchVk(vk::VulkanContext& context)
    : context_(context), state_(std::make_unique<State>(context)) {}

ConeSearchVk::~ConeSearchVk() = default;

void ConeSearchVk::set_points(std::span<const IsmPoint> points) {
  std::vector<float> packed;
  packed.reserve(std::max<std::size_t>(1, points.size()) * RELIGHT_CONE_POINT_FLOATS);
  for (const IsmPoint& p : points)
    packed.insert(packed.end(), {p.position.x(), p.position.y(), p.position.z(), p.half_size, p.normal.x(),
                                 p.normal.y(), p.normal.z(), 0.f});
  if (packed.empty()) packed.assign(RELIGHT_CONE_POINT_FLOATS, 0.f);  // a buffer may not be empty
  vk::reserve_with_headroom(state_->points, context_, packed.size() * sizeof(float));
  context_.transfer().upload(std::as_bytes(std::span<const float>(packed)), *state_->points);
  state_->point_count = static_cast<std::uint32_t>(points.size());
}

std::vector<ConeHit> ConeSearchVk::search(std::span<const ConeQuery> queries, float half_angle_deg) {
  if (!(half_angle_deg > 0.f && half_angle_deg < 90.f)) throw Error("the bounce cone needs an angle in (0, 90) degrees");
  std::vector<ConeHit> hits(queries.size());
  state_->gpu_ms.reset();
  if (queries.empty()) return hits;
  if (!state_->points) set_points({});
  std::vector<float> packed;
  packed.reserve(queries.size() * RELIGHT_CONE_QUERY_FLOATS);
  for (const ConeQuery& q : queries)
    packed.insert(packed.end(), {q.origin.x(), q.origin.y(), q.origin.z(), q.max_t, q.normal.x(), q.normal.y(),
                                 q.normal.z(), 0.f, q.direction.x(), q.direction.y(), q.direction.z(), 0.f});
  vk::VulkanTransfer& transfer = context_.transfer();
  vk::reserve_with_headroom(state_->queries, context_, packed.size() * sizeof(float));
  vk::reserve_with_headroom(state_->hits, context_, queries.size() * 2 * sizeof(std::uint32_t));
  vk::VulkanBuffer& query_buffer = *state_->queries;
  vk::VulkanBuffer& hit_buffer = *state_->hits;
  transfer.upload(std::as_bytes(std::span<const float>(packed)), query_buffer);
  const ConeShape cone(half_angle_deg);
  const gpu::ConeSearchParams params{state_->point_count, static_cast<gpu::uint>(queries.size()), cone.tan_half,
                                     cone.sin_half};
  State& s = *state_;
  const auto set = s.pipeline.bind({&*s.points, &query_buffer, &hit_buffer});
  context_.submit([&](VkCommandBuffer cmd) {
    s.timer.start(cmd);
    s.pipeline.dispatch(cmd, set, params, static_cast<std::uint32_t>(queries.size()), 1);
    s.timer.stop(cmd);
  });
  s.gpu_ms = s.timer.elapsed_ms();
  if (s.gpu_ms) s.untaken_ms += *s.gpu_ms;
  std::vector<std::uint32_t> words(queries.size() * 2);
  transfer.download(hit_buffer, std::as_writable_bytes(std::span(words)));
  for (std::size_t q = 0; q < queries.size(); ++q) {
    hits[q].point = words[2 * q + 1];
    hits[q].t = hits[q].point == ConeHit::kNone ? ConeHit{}.t : std::bit_cast<float>(words[2 * q]);
  }
  return hits;
}

std::optional<double> ConeSearchVk::last_gpu_ms() const { return state_->gpu_ms; }

double ConeSearchVk::take_gpu_ms() { return std::exchange(state_->untaken_ms, 0.0); }

}  // namespace relight::render
