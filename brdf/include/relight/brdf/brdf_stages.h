#pragma once
// Frame-graph stages of BRDF estimation (Knecht §4.4). Buffers (names configurable):
//
//   highlight_removal  reads ColorImage "color"
//                      writes ColorImage "color_diffuse" (highlights painted over), Mask "highlight_mask"
//   diffuse            reads "color_diffuse", PositionMap "positions", NormalMap "normals",
//                      LightSet "lights", FrameInfo "frame" (camera_to_world; identity when unknown)
//                      writes RadianceImage "kd", Mask "kd_valid"
//   kmeans (CPU|Vulkan) reads "kd", "kd_valid" (clusters the pixels marked 1, assigns those
//                      marked 2), "positions" (the clipped pixels, marked 3, take the label
//                      of the nearest clustered pixel of their surface, fill_clipped_labels);
//                      writes Materials "clusters" (centres as k_d,
//                      k_s = 0, ids = cluster + 1 on valid pixels); warm-started from its own
//                      previous result (KMeansTracker)
//   specular_fit       reads "clusters", "color", "highlight_mask", "positions", "normals",
//                      "lights", "frame"; writes Materials "materials" (k_s, n per cluster)
//
// add_brdf_stages() adds all four.
#include <memory>
#include <string>

#include "relight/brdf/buffers.h"
#include "relight/brdf/diffuse.h"
#include "relight/brdf/highlight.h"
#include "relight/brdf/kmeans.h"
#include "relight/brdf/materials.h"
#include "relight/brdf/specular_fit.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/core/stage_backend.h"
#include "relight/lights/buffers.h"
#include "relight/lights/light_set.h"

namespace relight::vk {
class VulkanContext;
}  // namespace relight::vk

namespace relight::brdf {

class SpecularObjectiveVk;

struct BrdfBuffers {
  BufferName<ColorImage> color = kColor;
  BufferName<PositionMap> positions = kPositions;
  BufferName<NormalMap> normals = kNormals;
  BufferName<lights::LightSet> lights = lights::kLights;
  BufferName<FrameInfo> frame = kFrame;
  BufferName<ColorImage> color_diffuse = kColorDiffuse;
  BufferName<Mask> highlight_mask = kHighlightMask;
  BufferName<RadianceImage> kd = kKd;
  BufferName<Mask> kd_valid = kKdValid;
  BufferName<Materials> clusters = kMaterialClusters;
  BufferName<Materials> materials = kMaterials;
  BufferName<KMeansTracker> kmeans_history = kKMeansHistory;
};

enum class SpecularMethod { NelderMead, Ceres };
[[nodiscard]] const char* to_string(SpecularMethod method);

struct BrdfOptions {
  HighlightOptions highlight;
  DiffuseOptions diffuse;
  KMeansOptions kmeans;
  SpecularOptions specular;
  SpecularMethod solver = SpecularMethod::NelderMead;
  int max_samples = 2048;               ///< per cluster
  Eigen::Vector3f ambient = Eigen::Vector3f::Zero();  ///< shading.h's A
  std::uint64_t seed = 1;               ///< K-means seeding
  int threads = 0;                      ///< clusters fitted in parallel
};

class HighlightRemovalStage final : public Stage {
 public:
  explicit HighlightRemovalStage(HighlightOptions options = {}, BrdfBuffers buffers = {})
      : options_(options), buffers_(std::move(buffers)) {}
  [[nodiscard]] std::string name() const override { return "highlight_removal"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  HighlightOptions options_;
  BrdfBuffers buffers_;
  Read<ColorImage> color_;
  Write<ColorImage> cleaned_;
  Write<Mask> mask_;
};

class DiffuseStage final : public Stage {
 public:
  explicit DiffuseStage(DiffuseOptions options = {}, Eigen::Vector3f ambient = Eigen::Vector3f::Zero(),
                        BrdfBuffers buffers = {})
      : options_(options), ambient_(ambient), buffers_(std::move(buffers)) {}
  [[nodiscard]] std::string name() const override { return "diffuse"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  DiffuseOptions options_;
  Eigen::Vector3f ambient_;
  BrdfBuffers buffers_;
  Read<ColorImage> color_;
  Read<PositionMap> positions_;
  Read<NormalMap> normals_;
  Read<lights::LightSet> lights_;
  Read<FrameInfo> frame_;
  Write<RadianceImage> kd_;
  Write<Mask> valid_;
};

/// K-means on the CPU engine, or on the Vulkan engine when `context` is not null (add_brdf_stages
/// chooses, core/stage_backend.h). Its buffers live on the host either way.
class KMeansStage final : public Stage {
 public:
  explicit KMeansStage(vk::VulkanContext* context, KMeansOptions options = {}, std::uint64_t seed = 1,
                       BrdfBuffers buffers = {});
  ~KMeansStage() override;
  [[nodiscard]] std::string name() const override { return "kmeans"; }
  [[nodiscard]] Backend backend() const override { return backend_; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const KMeansResult& last_result() const { return result_; }

 private:
  Backend backend_;
  std::unique_ptr<KMeansEngine> engine_;
  KMeansTracker first_tracker_;  ///< the state of the first frame (options and seed)
  BrdfBuffers buffers_;
  Read<RadianceImage> kd_;
  Read<Mask> valid_;
  Read<PositionMap> positions_;
  ReadPrevious<KMeansTracker> previous_tracker_;
  Write<KMeansTracker> tracker_;
  Write<Materials> clusters_;
  std::vector<Float3> points_;
  std::vector<std::uint32_t> pixels_;
  KMeansResult result_;
};

/// The specular fit on the CPU, or with each cluster's starting point chosen on the GPU
/// (fit_materials()'s gpu_start) when `context` is not null (add_brdf_stages chooses). Its
/// buffers (Materials, the samples it gathers) live on the host either way; the GPU start
/// uploads its own small batch of samples.
class SpecularFitStage final : public Stage {
 public:
  explicit SpecularFitStage(vk::VulkanContext* context, BrdfOptions options = {}, BrdfBuffers buffers = {});
  ~SpecularFitStage() override;
  [[nodiscard]] std::string name() const override { return "specular_fit"; }
  [[nodiscard]] Backend backend() const override { return gpu_start_ ? Backend::Vulkan : Backend::Cpu; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  BrdfOptions options_;
  BrdfBuffers buffers_;
  std::unique_ptr<SpecularSolver> solver_;
  std::unique_ptr<SpecularObjectiveVk> gpu_start_;
  Read<Materials> clusters_;
  Read<ColorImage> color_;
  Read<Mask> highlights_;
  Read<PositionMap> positions_;
  Read<NormalMap> normals_;
  Read<lights::LightSet> lights_;
  Read<FrameInfo> frame_;
  Write<Materials> materials_;
};

/// The four stages; K-means and the specular fit's starting points on Vulkan when `backend` is
/// Vulkan (needs `context`).
void add_brdf_stages(FrameGraph& graph, const BrdfOptions& options = {}, Backend backend = Backend::Cpu,
                     vk::VulkanContext* context = nullptr, const BrdfBuffers& buffers = {});

/// Clusters and materials for one frame without a graph (benchmarks, tools): the same work as the
/// four stages. `tracker` and `engine` carry the K-means state across frames.
struct BrdfFrame {
  ColorImage cleaned;
  Mask highlights;
  RadianceImage kd;
  Mask kd_valid;
  Materials materials;
};
void estimate_brdf(const ColorImage& color, const PositionMap& positions, const NormalMap& normals,
                   const ShadingLights& lights, const BrdfOptions& options, KMeansEngine& engine,
                   KMeansTracker& tracker, const SpecularSolver& solver, BrdfFrame& out);

/// Fits every cluster of `materials` (ids and k_d set) in parallel; fills k_s, n, fit_rms. With
/// `gpu_start`, each cluster's fit starts from the best of a dense (k_s, n) grid evaluated on the
/// GPU (best_grid_start()) instead of the solvers' own exponent grid.
void fit_materials(const ColorImage& color, const Mask* highlights, const PositionMap& positions,
                   const NormalMap& normals, const ShadingLights& lights, const BrdfOptions& options,
                   const SpecularSolver& solver, Materials& materials, SpecularObjectiveVk* gpu_start = nullptr);

/// Gives every clipped pixel (kd_valid kKdMarkClipped, diffuse.h) the label of the nearest labelled
/// pixel reachable over its own surface (neighbours whose depths differ by less than 3 % + 5 mm;
/// a chamfer distance by two raster sweeps, twice): the camera's value there is only a lower
/// bound, the surface's unclipped parts know its albedo. Clipped pixels no path reaches keep 0.
void fill_clipped_labels(LabelImage& ids, const Mask& valid, const PositionMap& positions);

/// Materials from a K-means result on the pixels `pixels` (indices into a width x height image).
[[nodiscard]] Materials materials_from_clusters(const KMeansResult& result, const std::vector<std::uint32_t>& pixels,
                                                int width, int height);

/// Gathers the K-means points (clamped k_d of valid pixels) and their pixel indices: first the
/// pixels marked 1 (clustered), then those marked 2 (only assigned, diffuse.h); returns how many
/// are clustered.
std::size_t gather_points(const RadianceImage& kd, const Mask& valid, std::vector<Float3>& points,
                          std::vector<std::uint32_t>& pixels);

/// Phong re-render of the estimated materials (camera frame), black where ids is 0.
[[nodiscard]] RadianceImage render_materials(const Materials& materials, const PositionMap& positions,
                                             const NormalMap& normals, const ShadingLights& lights);

}  // namespace relight::brdf
