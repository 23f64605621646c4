// Frame-graph stages of BRDF estimation (brdf_stages.h).
#include "relight/brdf/brdf_stages.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "relight/brdf/diffuse.h"
#include "relight/brdf/kmeans_vk.h"
#include "relight/brdf/specular_objective_vk.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::brdf {

namespace {

ShadingLights camera_lights(const lights::LightSet& set, const FrameInfo& frame, const Eigen::Vector3f& ambient) {
  return estimation_lights(set, frame.camera_to_world.value_or(Pose::Identity()), ambient);
}

std::unique_ptr<SpecularSolver> make_solver(SpecularMethod method) {
  return method == SpecularMethod::Ceres ? make_ceres_solver() : make_nelder_mead_solver();
}

}  // namespace

const char* to_string(SpecularMethod method) {
  return method == SpecularMethod::Ceres ? "ceres" : "nelder_mead";
}

std::size_t gather_points(const RadianceImage& kd, const Mask& valid, std::vector<Float3>& points,
                          std::vector<std::uint32_t>& pixels) {
  if (!kd.same_shape(valid)) throw Error("brdf K-means: k_d and its validity mask differ in size");
  points.clear();
  pixels.clear();
  points.reserve(kd.size());
  pixels.reserve(kd.size());
  for (const std::uint8_t mark : {std::uint8_t{1}, std::uint8_t{2}}) {
    for (std::size_t i = 0; i < kd.size(); ++i) {
      if (valid.pixels()[i] != mark) continue;
      points.push_back(kmeans_feature(kd.pixels()[i]));
      pixels.push_back(static_cast<std::uint32_t>(i));
    }
  }
  return static_cast<std::size_t>(std::count(valid.pixels().begin(), valid.pixels().end(), std::uint8_t{1}));
}

void fill_clipped_labels(LabelImage& ids, const Mask& valid, const PositionMap& positions) {
  if (!ids.same_shape(valid) || !ids.same_shape(positions))
    throw Error("brdf: the labels, the k_d validity and the positions differ in size");
  const int width = ids.width(), height = ids.height();
  constexpr float kUnreached = std::numeric_limits<float>::infinity();
  std::vector<float> distance(ids.size(), kUnreached);
  bool any_clipped = false;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids.pixels()[i] != 0) distance[i] = 0.f;
    any_clipped = any_clipped || valid.pixels()[i] == kKdMarkClipped;
  }
  if (!any_clipped) return;
  const auto depth = [&](int r, int c) { return positions(r, c).z; };
  // Relaxes clipped pixel (r, c) from neighbour (r + dr, c + dc), one step of length `step`.
  const auto relax = [&](int r, int c, int dr, int dc, float step) {
    const int nr = r + dr, nc = c + dc;
    if (nr < 0 || nc < 0 || nr >= height || nc >= width) return;
    const auto i = static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c);
    const auto n = static_cast<std::size_t>(nr) * static_cast<std::size_t>(width) + static_cast<std::size_t>(nc);
    if (ids.pixels()[n] == 0 || distance[n] + step >= distance[i]) return;
    const float a = depth(r, c), b = depth(nr, nc);
    if (!is_valid_depth(a) || !is_valid_depth(b) || std::abs(a - b) > 0.03f * std::min(a, b) + 0.005f) return;
    distance[i] = distance[n] + step;
    ids.pixels()[i] = ids.pixels()[n];
  };
  constexpr float kDiagonal = 1.41421356f;
  for (int sweep = 0; sweep < 2; ++sweep) {
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) {
        if (valid(r, c) != kKdMarkClipped) continue;
        relax(r, c, 0, -1, 1.f), relax(r, c, -1, -1, kDiagonal), relax(r, c, -1, 0, 1.f), relax(r, c, -1, 1, kDiagonal);
      }
    for (int r = height - 1; r >= 0; --r)
      for (int c = width - 1; c >= 0; --c) {
        if (valid(r, c) != kKdMarkClipped) continue;
        relax(r, c, 0, 1, 1.f), relax(r, c, 1, 1, kDiagonal), relax(r, c, 1, 0, 1.f), relax(r, c, 1, -1, kDiagonal);
      }
  }
}

Materials materials_from_clusters(const KMeansResult& result, const std::vector<std::uint32_t>& pixels, int width,
                                  int height) {
  Materials m;
  m.ids = LabelImage(width, height);
  m.clusters.resize(result.centres.size());
  for (std::size_t k = 0; k < result.centres.size(); ++k) m.clusters[k].kd = result.centres[k];
  for (std::size_t i = 0; i < pixels.size() && i < result.labels.size(); ++i) {
    m.ids.pixels()[pixels[i]] = static_cast<std::uint16_t>(result.labels[i] + 1);
    ++m.clusters[result.labels[i]].pixels;
  }
  return m;
}

void fit_materials(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                   const NormalMap& normals, const ShadingLights& lights, const BrdfOptions& options,
                   const SpecularSolver& solver, Materials& materials, SpecularObjectiveVk* gpu_start) {
  const int clusters = static_cast<int>(materials.clusters.size());
  std::vector<std::vector<SpecularSample>> samples =
      select_cluster_samples(color, positions, normals, materials.ids, clusters, highlights, options.max_samples);
  std::vector<SpecularProblem> problems(static_cast<std::size_t>(clusters));
  std::vector<SpecularOptions> starts(problems.size(), options.specular);
  for (std::size_t k = 0; k < problems.size(); ++k) {
    problems[k].kd = materials.clusters[k].kd;
    problems[k].lights = lights;
    problems[k].samples = std::move(samples[k]);
    // One GPU submission per cluster, before the parallel fits (the queue is not shared).
    if (gpu_start && !problems[k].samples.empty()) {
      starts[k].start = best_grid_start(*gpu_start, problems[k], options.specular);
    }
  }
  parallel_rows(
      clusters, options.threads,
      [&](int begin, int end) {
        for (int k = begin; k < end; ++k) {
          const auto index = static_cast<std::size_t>(k);
          MaterialParams& m = materials.clusters[index];
          if (problems[index].samples.empty()) {
            m.ks = 0.f;
            m.fit_rms = -1.f;
            continue;
          }
          const SpecularFit fit = solver.fit(problems[index], starts[index]);
          m.ks = fit.ks;
          m.n = fit.n;
          m.fit_rms = static_cast<float>(fit.rms);
        }
      },
      1);
}

void estimate_brdf(const ColorImage& color, const PositionMap& positions, const NormalMap& normals,
                   const ShadingLights& lights, const BrdfOptions& options, KMeansEngine& engine,
                   KMeansTracker& tracker, const SpecularSolver& solver, BrdfFrame& out) {
  remove_highlights(color, options.highlight, out.cleaned, out.highlights);
  estimate_diffuse(out.cleaned, positions, normals, lights, options.diffuse, out.kd, out.kd_valid);
  std::vector<Float3> points;
  std::vector<std::uint32_t> pixels;
  const std::size_t clustered = gather_points(out.kd, out.kd_valid, points, pixels);
  const KMeansResult result = tracker.run(engine, points, clustered);
  out.materials = materials_from_clusters(result, pixels, color.width(), color.height());
  fill_clipped_labels(out.materials.ids, out.kd_valid, positions);
  fit_materials(color, &out.highlights, positions, normals, lights, options, solver, out.materials);
}

RadianceImage render_materials(const Materials& materials, const PositionMap& positions, const NormalMap& normals,
                               const ShadingLights& lights) {
  RadianceImage out(materials.ids.width(), materials.ids.height());
  parallel_for_each_row(out.height(), 0, [&](int r) {
    for (int c = 0; c < out.width(); ++c) {
      const int id = materials.ids(r, c);
      if (id == 0) continue;
      const MaterialParams& m = materials.clusters[static_cast<std::size_t>(id - 1)];
      const Float3 p = positions(r, c), n = normals(r, c);
      const Eigen::Vector3f l = phong_radiance(lights, {p.x, p.y, p.z}, {n.x, n.y, n.z}, m.kd, m.ks, m.n);
      out(r, c) = {l.x(), l.y(), l.z()};
    }
  });
  return out;
}

void HighlightRemovalStage::declare(StageBuilder& builder) {
  color_ = builder.read(buffers_.color);
  cleaned_ = builder.write(buffers_.color_diffuse);
  mask_ = builder.write(buffers_.highlight_mask);
}

void HighlightRemovalStage::run(StageContext& context) {
  remove_highlights(context.get(color_), options_, context.get(cleaned_), context.get(mask_));
}

void DiffuseStage::declare(StageBuilder& builder) {
  color_ = builder.read(buffers_.color_diffuse);
  positions_ = builder.read(buffers_.positions);
  normals_ = builder.read(buffers_.normals);
  lights_ = builder.read(buffers_.lights);
  frame_ = builder.read(buffers_.frame);
  kd_ = builder.write(buffers_.kd);
  valid_ = builder.write(buffers_.kd_valid);
}

void DiffuseStage::run(StageContext& context) {
  const ShadingLights lights = camera_lights(context.get(lights_), context.get(frame_), ambient_);
  estimate_diffuse(context.get(color_), context.get(positions_), context.get(normals_), lights, options_,
                   context.get(kd_), context.get(valid_));
}

namespace {

std::unique_ptr<KMeansEngine> kmeans_engine(vk::VulkanContext* context, const KMeansOptions& options) {
  if (context) return std::make_unique<KMeansVk>(*context);
  return std::make_unique<KMeansCpu>(options.threads);
}

}  // namespace

KMeansStage::KMeansStage(vk::VulkanContext* context, KMeansOptions options, std::uint64_t seed, BrdfBuffers buffers)
    : backend_(context ? Backend::Vulkan : Backend::Cpu),
      engine_(kmeans_engine(context, options)),
      first_tracker_(options, seed),
      buffers_(std::move(buffers)) {}

KMeansStage::~KMeansStage() = default;

void KMeansStage::declare(StageBuilder& builder) {
  kd_ = builder.read(buffers_.kd);
  valid_ = builder.read(buffers_.kd_valid);
  positions_ = builder.read(buffers_.positions);
  previous_tracker_ = builder.read_previous(buffers_.kmeans_history);
  tracker_ = builder.write(buffers_.kmeans_history);
  clusters_ = builder.write(buffers_.clusters);
}

void KMeansStage::run(StageContext& context) {
  const RadianceImage& kd = context.get(kd_);
  const std::size_t clustered = gather_points(kd, context.get(valid_), points_, pixels_);
  if (auto* gpu = dynamic_cast<KMeansVk*>(engine_.get())) gpu->reset_gpu_ms();
  const KMeansTracker* previous = context.get(previous_tracker_);
  KMeansTracker& tracker = context.get(tracker_);
  tracker = previous ? *previous : first_tracker_;
  result_ = tracker.run(*engine_, points_, clustered);
  if (auto* gpu = dynamic_cast<KMeansVk*>(engine_.get()); gpu && gpu->gpu_ms()) context.report_device_ms(*gpu->gpu_ms());
  Materials& materials = context.get(clusters_);
  materials = materials_from_clusters(result_, pixels_, kd.width(), kd.height());
  fill_clipped_labels(materials.ids, context.get(valid_), context.get(positions_));
}

SpecularFitStage::SpecularFitStage(vk::VulkanContext* context, BrdfOptions options, BrdfBuffers buffers)
    : options_(std::move(options)), buffers_(std::move(buffers)), solver_(make_solver(options_.solver)) {
  if (context) gpu_start_ = std::make_unique<SpecularObjectiveVk>(*context);
}

SpecularFitStage::~SpecularFitStage() = default;

void SpecularFitStage::declare(StageBuilder& builder) {
  clusters_ = builder.read(buffers_.clusters);
  color_ = builder.read(buffers_.color);
  highlights_ = builder.read(buffers_.highlight_mask);
  positions_ = builder.read(buffers_.positions);
  normals_ = builder.read(buffers_.normals);
  lights_ = builder.read(buffers_.lights);
  frame_ = builder.read(buffers_.frame);
  materials_ = builder.write(buffers_.materials);
}

void SpecularFitStage::run(StageContext& context) {
  Materials& out = context.get(materials_);
  out = context.get(clusters_);
  const ShadingLights lights = camera_lights(context.get(lights_), context.get(frame_), options_.ambient);
  if (gpu_start_) gpu_start_->reset_gpu_ms();
  fit_materials(context.get(color_), &context.get(highlights_), context.get(positions_), context.get(normals_), lights,
                options_, *solver_, out, gpu_start_.get());
  if (const auto gpu_ms = gpu_start_ ? gpu_start_->gpu_ms() : std::nullopt) context.report_device_ms(*gpu_ms);
}

void add_brdf_stages(FrameGraph& graph, const BrdfOptions& options, Backend backend, vk::VulkanContext* context,
                     const BrdfBuffers& buffers) {
  graph.emplace<HighlightRemovalStage>(options.highlight, buffers);
  graph.emplace<DiffuseStage>(options.diffuse, options.ambient, buffers);
  vk::VulkanContext* device = context_for_backend(backend, context, "add_brdf_stages");
  graph.emplace<KMeansStage>(device, options.kmeans, options.seed, buffers);
  graph.emplace<SpecularFitStage>(device, options, buffers);
}

}  // namespace relight::brdf
