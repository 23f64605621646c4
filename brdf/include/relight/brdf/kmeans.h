#pragma once
// K-means (Lloyd) on per-pixel diffuse reflectance (Knecht §4.4.3), CPU reference and the
// policy that runs it every frame.
//
// One Lloyd iteration assigns every point to its nearest centre (squared Euclidean distance in
// float, evaluated as ((dx*dx + dy*dy) + dz*dz) without contraction; ties go to the lower index)
// and accumulates, per cluster, the colour sum, the count and the sum of squared distances. The
// sums are fixed-point integers (brdf_shared.h), so they are exact and do not depend on the order
// of addition: the multi-threaded CPU loop and the Vulkan dispatch (kmeans_vk.h) produce
// identical sums, centres and assignments from the same initial centres.
//
// A run iterates at most max_iterations times and stops when the total variance (the sum of
// squared distances, "compactness") changes by less than epsilon relative to the previous
// iteration. Centres are updated to the cluster means after each assignment; an empty cluster
// keeps its centre. The result's labels are the last assignment and its compactness the sum of
// squared distances of that assignment.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "relight/brdf/brdf_shared.h"
#include "relight/core/pixel.h"
#include "relight/core/worker_pool.h"

namespace relight::brdf {

struct KMeansOptions {
  int clusters = 6;          ///< K, 1..16
  int max_iterations = 20;
  double epsilon = 1e-4;     ///< relative change of the total variance that counts as converged
  int threads = 0;           ///< CPU threads (0 = worker_count(0))
  /// KMeansTracker: centres closer than this (Euclidean, k_d units) describe one material.
  float merge_distance = 0.05f;
};

struct KMeansResult {
  std::vector<Eigen::Vector3f> centres;
  std::vector<std::uint8_t> labels;  ///< per point, cluster index
  double compactness = 0.0;          ///< sum of squared distances of the last assignment
  int iterations = 0;
  bool converged = false;
};

/// Exact per-cluster sums of one assignment step (fixed point, see brdf_shared.h).
struct ClusterSums {
  struct Cluster {
    std::uint64_t sum[3] = {0, 0, 0};
    std::uint64_t count = 0;
    std::uint64_t distance = 0;
  };
  std::vector<Cluster> clusters;
  [[nodiscard]] double total_variance() const;
  /// Means of non-empty clusters; empty clusters keep `centres[k]`.
  void update(std::vector<Eigen::Vector3f>& centres) const;
};

/// A feature clamped to the K-means range [0, RELIGHT_KMEANS_FEATURE_MAX] (non-finite: 0).
[[nodiscard]] inline Float3 kmeans_feature(const Float3& v) {
  auto clamp = [](float x) {
    return std::isfinite(x) ? std::min(std::max(x, 0.f), static_cast<float>(RELIGHT_KMEANS_FEATURE_MAX)) : 0.f;
  };
  return {clamp(v.x), clamp(v.y), clamp(v.z)};
}

/// One Lloyd implementation: step() assigns and sums; the loop around it is shared (lloyd()).
class KMeansEngine {
 public:
  virtual ~KMeansEngine() = default;
  /// Makes `points` (already clamped features) the data of the following step() calls.
  virtual void set_points(std::span<const Float3> points) = 0;
  /// Restricts the following step() and read_labels() calls to the first `count` points of the
  /// last set_points() (at most all of them), without setting them again.
  virtual void use_first(std::size_t count) = 0;
  /// One assignment + reduction with `centres`.
  virtual ClusterSums step(std::span<const Eigen::Vector3f> centres) = 0;
  /// The assignment of the last step(), one cluster index per point.
  virtual void read_labels(std::vector<std::uint8_t>& labels) = 0;
};

/// Which build of the CPU step's inner loop runs (both give identical results).
enum class KMeansCpuKernel {
  Fastest,   ///< AVX2 where the CPU has it, else portable
  Portable,  ///< plain C++ (for CPUs without AVX2, and to test the two against each other)
};

/// The CPU engine: points split into chunks of 8192 over a WorkerPool, each assigned and summed
/// eight at a time with AVX2 where the CPU has it (a portable loop otherwise), integer sums per
/// chunk added up.
class KMeansCpu final : public KMeansEngine {
 public:
  explicit KMeansCpu(int threads = 0, KMeansCpuKernel kernel = KMeansCpuKernel::Fastest);
  ~KMeansCpu() override;
  KMeansCpu(KMeansCpu&&) noexcept;
  KMeansCpu& operator=(KMeansCpu&&) noexcept;
  void set_points(std::span<const Float3> points) override;
  void use_first(std::size_t count) override { active_ = std::min(count, xs_.size()); }
  ClusterSums step(std::span<const Eigen::Vector3f> centres) override;
  void read_labels(std::vector<std::uint8_t>& labels) override { labels = labels_; }

 private:
  int threads_;
  KMeansCpuKernel kernel_;
  std::unique_ptr<WorkerPool> pool_;         // of `threads_` workers, made on the first parallel step
  std::size_t active_ = 0;                   // points that step() works on
  std::vector<float> xs_, ys_, zs_;  // points, structure of arrays
  std::vector<std::uint8_t> labels_;
};

/// Lloyd iterations from `initial` centres on the engine's points.
[[nodiscard]] KMeansResult lloyd(KMeansEngine& engine, std::vector<Eigen::Vector3f> initial,
                                 const KMeansOptions& options);

/// k-means++ defaults: greedy candidates per centre, and the most points seeding looks at.
inline constexpr int kKMeansPpTrials = 3;
inline constexpr std::size_t kKMeansPpMaxPoints = 32768;

/// k-means++ seeding (Arthur & Vassilvitskii): first centre uniform, then D^2 sampling, greedy
/// with `trials` candidates per centre (the lowest potential wins, as in cv::kmeans), on an
/// even-stride subset of at most `max_points` points (0: all).
[[nodiscard]] std::vector<Eigen::Vector3f> kmeans_pp_centres(std::span<const Float3> points, int clusters,
                                                             std::mt19937_64& rng, int trials = kKMeansPpTrials,
                                                             std::size_t max_points = kKMeansPpMaxPoints);

/// `attempts` runs from k-means++ seeds, the lowest compactness kept (cv::kmeans' setting); the
/// seeding subset is gathered once for all attempts.
[[nodiscard]] KMeansResult kmeans(KMeansEngine& engine, std::span<const Float3> points, const KMeansOptions& options,
                                  int attempts, std::mt19937_64& rng);

/// The per-frame policy of the issue: a warm start from the previous frame's centres; when that
/// does not converge, and on every `random_every`-th frame regardless, also a run from k-means++
/// seeds, keeping the lower compactness. The first frame (or after reset) runs from seeds only.
///
/// Then, as in ISODATA's merge step, two centres closer than merge_distance count as one
/// material split in two (a glossy surface's residual sheen, or shading error, spreads its k_d
/// along a line; Lloyd minimises the total variance by spending a cluster on that spread rather
/// than on a small object of another colour): one of them moves to the point farthest from its
/// centre and Lloyd runs again, kept while the compactness drops (at most K - 1 times).
class KMeansTracker {
 public:
  /// As a frame-graph buffer (KMeansStage's history, brdf/buffers.h).
  static constexpr const char* type_name = "KMeansTracker";
  explicit KMeansTracker(KMeansOptions options = {}, std::uint64_t seed = 1, int random_every = 5)
      : options_(options), rng_(seed), random_every_(random_every) {}
  /// Clusters this frame's points (clamped features).
  [[nodiscard]] KMeansResult run(KMeansEngine& engine, std::span<const Float3> points);
  /// Clusters the first `clustered` points and then assigns every point to the nearest of the
  /// resulting centres (one more step on all points): the labels cover all points, the
  /// compactness is the clustering's. `clustered` 0 or all: run(engine, points).
  [[nodiscard]] KMeansResult run(KMeansEngine& engine, std::span<const Float3> points, std::size_t clustered);
  void reset() { previous_.reset(); frame_ = 0; }
  [[nodiscard]] const KMeansOptions& options() const { return options_; }
  /// What the last run() did, for tests and reports.
  [[nodiscard]] bool last_used_warm_start() const { return last_warm_; }
  [[nodiscard]] bool last_ran_random() const { return last_random_; }

 private:
  /// Labels of all points for `result`'s centres (one step when some points were not clustered);
  /// returns the total variance of all points.
  double assign_all(KMeansEngine& engine, std::span<const Float3> points, std::size_t clustered,
                    KMeansResult& result) const;
  void separate_merged_centres(KMeansEngine& engine, std::span<const Float3> points, std::size_t clustered,
                               KMeansResult& result, double variance) const;

  KMeansOptions options_;
  std::mt19937_64 rng_;
  int random_every_;
  std::int64_t frame_ = 0;
  std::optional<std::vector<Eigen::Vector3f>> previous_;
  bool last_warm_ = false;
  bool last_random_ = false;
};

/// Adjusted Rand index (Hubert & Arabie) of two labelings of the same points.
[[nodiscard]] double adjusted_rand_index(std::span<const int> a, std::span<const int> b);

}  // namespace relight::brdf
