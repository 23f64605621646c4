// The specular objective on the GPU (specular_objective_vk.h).
#include "relight/brdf/specular_objective_vk.h"

#include <algorithm>
#include <string>

#include "relight/brdf/specular_shared.h"
#include "relight/core/error.h"
#include "relight/shaders/brdf_specular_objective_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "specular_model.h"
#include "specular_terms.h"

namespace relight::brdf {

namespace {

constexpr std::uint32_t kGroup = RELIGHT_SPECULAR_GROUP;

gpu::vec4 vec4(const Eigen::Vector3f& v, float w = 0.f) { return {v.x(), v.y(), v.z(), w}; }

/// Grows `buffer` to hold at least `bytes` (host-visible `domain`); returns true when replaced.
bool ensure(std::optional<vk::VulkanBuffer>& buffer, vk::VulkanContext& context, std::size_t bytes,
            vk::BufferDomain domain) {
  if (buffer && buffer->size_bytes() >= bytes) return false;
  buffer.emplace(context, std::max<std::size_t>(bytes, 256), domain);
  return true;
}

}  // namespace

struct SpecularObjectiveVk::Resources {
  explicit Resources(vk::VulkanContext& context)
      : pipeline(context, {.spirv = shaders::brdf_specular_objective_comp,
                           .storage_buffers = 4,
                           .push_constant_bytes = sizeof(gpu::SpecularObjectiveParams),
                           .max_descriptor_sets = 2}),
        timer(context) {}
  vk::ComputePipeline pipeline;
  vk::GpuTimer timer;
  // All host-visible: the batch is written and read by the host around one submission.
  std::optional<vk::VulkanBuffer> samples, lights, candidates, partials;
  vk::UniqueDescriptorSet set;
};

SpecularObjectiveVk::SpecularObjectiveVk(vk::VulkanContext& context)
    : context_(context), resources_(std::make_unique<Resources>(context)) {}

SpecularObjectiveVk::~SpecularObjectiveVk() = default;

std::vector<double> SpecularObjectiveVk::evaluate(const SpecularProblem& problem, const SpecularOptions& options,
                                                  std::span<const SpecularCandidate> candidates) {
  std::vector<double> objective(candidates.size(), 0.0);
  if (candidates.empty() || problem.samples.empty()) return objective;
  if (problem.lights.lights.size() > RELIGHT_SPECULAR_MAX_LIGHTS) {
    throw Error("brdf specular (Vulkan): at most " + std::to_string(RELIGHT_SPECULAR_MAX_LIGHTS) + " lights");
  }
  const std::uint32_t groups = vk::ComputePipeline::group_count(static_cast<std::uint32_t>(problem.samples.size()), kGroup);
  if (candidates.size() > 65535 || groups > 65535) throw Error("brdf specular (Vulkan): batch too large");

  const std::vector<int> moving_ids = moving_light_indices(problem.lights, options.moving_lights);
  const ShadingLights ordered = detail::moving_first(problem.lights, moving_ids);
  std::vector<gpu::vec4> samples, lights, packed;
  samples.reserve(problem.samples.size() * RELIGHT_SPECULAR_SAMPLE_VEC4S);
  for (const SpecularSample& s : problem.samples) {
    samples.push_back(vec4(s.radiance));
    samples.push_back(vec4(s.position));
    samples.push_back(vec4(s.normal));
  }
  for (const ShadingLight& l : ordered.lights) {
    lights.push_back(vec4(l.vector, l.point ? 1.f : 0.f));
    lights.push_back(vec4(l.power));
  }
  for (const SpecularCandidate& c : candidates) {
    packed.push_back({c.ks, c.n, 0.f, 0.f});
    for (const Eigen::Vector3f& offset : c.offsets) packed.push_back(vec4(offset));
  }

  Resources& r = *resources_;
  const std::size_t partial_count = candidates.size() * groups;
  bool grown = ensure(r.samples, context_, samples.size() * sizeof(gpu::vec4), vk::BufferDomain::Upload);
  grown = ensure(r.lights, context_, std::max<std::size_t>(1, lights.size()) * sizeof(gpu::vec4),
                 vk::BufferDomain::Upload) || grown;
  grown = ensure(r.candidates, context_, packed.size() * sizeof(gpu::vec4), vk::BufferDomain::Upload) || grown;
  grown = ensure(r.partials, context_, partial_count * sizeof(float), vk::BufferDomain::Readback) || grown;
  if (grown || !r.set) {
    r.set = {};
    r.set = r.pipeline.bind({&*r.samples, &*r.lights, &*r.candidates, &*r.partials});
  }
  r.samples->write(std::as_bytes(std::span<const gpu::vec4>(samples)));
  if (!lights.empty()) r.lights->write(std::as_bytes(std::span<const gpu::vec4>(lights)));
  r.candidates->write(std::as_bytes(std::span<const gpu::vec4>(packed)));

  const gpu::SpecularObjectiveParams params{
      static_cast<std::uint32_t>(problem.samples.size()), static_cast<std::uint32_t>(ordered.lights.size()),
      static_cast<std::uint32_t>(moving_ids.size()), groups, vec4(problem.kd), vec4(ordered.ambient)};
  context_.submit([&](VkCommandBuffer cmd) {
    r.timer.start(cmd);
    r.pipeline.dispatch(cmd, r.set, params, groups, static_cast<std::uint32_t>(candidates.size()));
    r.timer.stop(cmd);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT);
  });
  if (const auto ms = r.timer.elapsed_ms()) gpu_ms_ = gpu_ms_.value_or(0.0) + *ms;
  std::vector<float> partials(partial_count);
  r.partials->read(std::as_writable_bytes(std::span<float>(partials)));
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    for (std::uint32_t g = 0; g < groups; ++g) objective[c] += partials[c * groups + g];
  }
  return objective;
}

std::vector<SpecularCandidate> specular_start_grid(const SpecularOptions& options, int exponents, int strengths) {
  strengths = std::max(2, strengths);
  std::vector<SpecularCandidate> grid;
  for (const double n : detail::log_spaced_exponents(options, exponents)) {
    for (int s = 0; s < strengths; ++s) {
      SpecularCandidate c;
      c.n = static_cast<float>(n);
      c.ks = options.ks_max * static_cast<float>(s) / static_cast<float>(strengths - 1);
      grid.push_back(c);
    }
  }
  return grid;
}

SpecularStart best_grid_start(SpecularObjectiveVk& objective, const SpecularProblem& problem,
                              const SpecularOptions& options, int exponents, int strengths) {
  const std::vector<SpecularCandidate> grid = specular_start_grid(options, exponents, strengths);
  const std::vector<double> f = objective.evaluate(problem, options, grid);
  const auto best = static_cast<std::size_t>(std::min_element(f.begin(), f.end()) - f.begin());
  return {grid[best].ks, grid[best].n};
}

}  // namespace relight::brdf
