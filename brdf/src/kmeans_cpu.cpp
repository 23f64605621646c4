// K-means CPU engine, the shared Lloyd loop, seeding and the per-frame policy (kmeans.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "kmeans_step_kernel.h"
#include "relight/brdf/brdf_shared.h"
#include "relight/brdf/kmeans.h"
#include "relight/core/cpu_dispatch.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/core/worker_pool.h"

namespace relight::brdf {

namespace {

constexpr std::size_t kChunk = 8192;

void check_clusters(std::size_t clusters) {
  if (clusters < 1 || clusters > RELIGHT_KMEANS_MAX_CLUSTERS) {
    throw Error("brdf K-means: the number of clusters must be 1.." + std::to_string(RELIGHT_KMEANS_MAX_CLUSTERS));
  }
}

}  // namespace

double ClusterSums::total_variance() const {
  std::uint64_t total = 0;
  for (const Cluster& c : clusters) total += c.distance;
  return static_cast<double>(total) / RELIGHT_KMEANS_DISTANCE_SCALE;
}

void ClusterSums::update(std::vector<Eigen::Vector3f>& centres) const {
  for (std::size_t k = 0; k < clusters.size() && k < centres.size(); ++k) {
    const Cluster& c = clusters[k];
    if (c.count == 0) continue;
    const double scale = 1.0 / (RELIGHT_KMEANS_VALUE_SCALE * static_cast<double>(c.count));
    centres[k] = Eigen::Vector3f(static_cast<float>(static_cast<double>(c.sum[0]) * scale),
                                 static_cast<float>(static_cast<double>(c.sum[1]) * scale),
                                 static_cast<float>(static_cast<double>(c.sum[2]) * scale));
  }
}

KMeansCpu::KMeansCpu(int threads, KMeansCpuKernel kernel) : threads_(threads), kernel_(kernel) {}
KMeansCpu::~KMeansCpu() = default;
KMeansCpu::KMeansCpu(KMeansCpu&&) noexcept = default;
KMeansCpu& KMeansCpu::operator=(KMeansCpu&&) noexcept = default;

void KMeansCpu::set_points(std::span<const Float3> points) {
  const std::size_t n = points.size();
  xs_.resize(n);
  ys_.resize(n);
  zs_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    xs_[i] = points[i].x;
    ys_[i] = points[i].y;
    zs_[i] = points[i].z;
  }
  active_ = n;
}

ClusterSums KMeansCpu::step(std::span<const Eigen::Vector3f> centres) {
  const std::size_t k_count = centres.size();
  check_clusters(k_count);
  const std::size_t n = active_;
  labels_.resize(n);
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<ClusterSums::Cluster> partial(chunks * k_count);
  detail::KMeansCentres soa;
  soa.count = static_cast<int>(k_count);
  for (std::size_t k = 0; k < k_count; ++k) {
    soa.x[k] = centres[k].x();
    soa.y[k] = centres[k].y();
    soa.z[k] = centres[k].z();
  }
  // A pool kept by the engine rather than parallel_rows()'s per call: its workers stay alive
  // between the 20-100 steps of a run, and a chunk that no worker has taken yet runs on the
  // calling thread instead of waiting for a helper thread to be scheduled (on a loaded machine
  // that wait cost more than the step).
  const auto run_chunks = [&](int begin, int end) {
    for (int chunk = begin; chunk < end; ++chunk) {
      const std::size_t first = static_cast<std::size_t>(chunk) * kChunk;
      const std::size_t count = std::min(n, first + kChunk) - first;
      detail::kmeans_assign_and_sum(xs_.data() + first, ys_.data() + first, zs_.data() + first, count, soa,
                                    labels_.data() + first, partial.data() + static_cast<std::size_t>(chunk) * k_count,
                                    kernel_ == KMeansCpuKernel::Portable);
    }
  };
  if (worker_count(threads_) <= 1 || chunks <= 1) {
    run_chunks(0, static_cast<int>(chunks));
  } else {
    if (!pool_) pool_ = std::make_unique<WorkerPool>(threads_);
    pool_->for_ranges(static_cast<int>(chunks), run_chunks, 1);
  }
  ClusterSums total;
  total.clusters.resize(k_count);
  for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
    for (std::size_t k = 0; k < k_count; ++k) {
      const ClusterSums::Cluster& s = partial[chunk * k_count + k];
      ClusterSums::Cluster& t = total.clusters[k];
      for (int c = 0; c < 3; ++c) t.sum[c] += s.sum[c];
      t.count += s.count;
      t.distance += s.distance;
    }
  }
  return total;
}

KMeansResult lloyd(KMeansEngine& engine, std::vector<Eigen::Vector3f> initial, const KMeansOptions& options) {
  check_clusters(initial.size());
  KMeansResult result;
  result.centres = std::move(initial);
  double previous = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    const ClusterSums sums = engine.step(result.centres);
    const double variance = sums.total_variance();
    sums.update(result.centres);
    result.compactness = variance;
    result.iterations = iteration + 1;
    if (std::isfinite(previous) && std::abs(previous - variance) <= options.epsilon * previous) {
      result.converged = true;
      break;
    }
    previous = variance;
  }
  engine.read_labels(result.labels);
  return result;
}

namespace {

/// The points k-means++ seeds from, structure of arrays (vectorises without shuffles).
struct SeedPoints {
  std::vector<float> x, y, z;
  [[nodiscard]] std::size_t size() const { return x.size(); }
  [[nodiscard]] Eigen::Vector3f operator[](std::size_t i) const { return {x[i], y[i], z[i]}; }
};

/// nearest[i] = min(previous[i], |point i - centre|^2) (nearest may alias previous); returns the
/// sum (the k-means++ potential). Eight running sums, so that the sum vectorises too.
RELIGHT_AVX2_CLONES double nearest_squared_distances(const float* x, const float* y, const float* z, std::size_t n,
                                                     float cx, float cy, float cz, const float* previous,
                                                     float* nearest) {
  for (std::size_t i = 0; i < n; ++i) {
    const float dx = x[i] - cx, dy = y[i] - cy, dz = z[i] - cz;
    nearest[i] = std::min(previous[i], dx * dx + dy * dy + dz * dz);
  }
  double lanes[8] = {};
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    for (std::size_t l = 0; l < 8; ++l) lanes[l] += nearest[i + l];
  }
  double total = 0.0;
  for (; i < n; ++i) total += nearest[i];
  for (const double lane : lanes) total += lane;
  return total;
}

double nearest_squared_distances(const SeedPoints& p, const Eigen::Vector3f& centre, const std::vector<float>& previous,
                                 std::vector<float>& nearest) {
  return nearest_squared_distances(p.x.data(), p.y.data(), p.z.data(), p.size(), centre.x(), centre.y(), centre.z(),
                                   previous.data(), nearest.data());
}

/// An even-stride subset of at most `max_points` points (0: all): the D^2 distribution of a few
/// ten thousand points is the same for seeding purposes and keeps the greedy trials cheap.
SeedPoints seed_points(std::span<const Float3> all_points, std::size_t max_points) {
  if (all_points.empty()) throw Error("brdf K-means: no points to seed from");
  std::size_t stride = 1;
  if (max_points > 0 && all_points.size() > max_points) stride = (all_points.size() + max_points - 1) / max_points;
  SeedPoints points;
  const std::size_t n = (all_points.size() + stride - 1) / stride;
  points.x.resize(n);
  points.y.resize(n);
  points.z.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Float3& p = all_points[i * stride];
    points.x[i] = p.x;
    points.y[i] = p.y;
    points.z[i] = p.z;
  }
  return points;
}

std::vector<Eigen::Vector3f> seed_centres(const SeedPoints& points, int clusters, std::mt19937_64& rng, int trials) {
  check_clusters(static_cast<std::size_t>(clusters));
  const std::size_t n = points.size();
  std::vector<Eigen::Vector3f> centres;
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  centres.push_back(points[pick(rng)]);
  std::vector<float> d2(n, std::numeric_limits<float>::infinity()), trial_d2(n), best_d2(n);
  std::vector<double> cumulative(n);
  double potential = nearest_squared_distances(points, centres[0], d2, d2);
  while (static_cast<int>(centres.size()) < clusters) {
    // Greedy k-means++ (as cv::kmeans and scikit-learn): `trials` candidates drawn by D^2, the
    // one that lowers the potential most wins. All trials draw from the same distribution, so its
    // cumulative sum is built once and each draw is a binary search.
    double running = 0.0;
    for (std::size_t i = 0; i < n; ++i) cumulative[i] = running += d2[i];
    double best_potential = std::numeric_limits<double>::infinity();
    Eigen::Vector3f best_centre = centres.back();
    for (int t = 0; t < std::max(1, trials); ++t) {
      std::size_t chosen = pick(rng);
      if (potential > 0.0) {
        const double target = unit(rng) * running;
        chosen = std::min<std::size_t>(
            n - 1, static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), target) -
                                            cumulative.begin()));
      }
      const Eigen::Vector3f candidate = points[chosen];
      const double trial_potential = nearest_squared_distances(points, candidate, d2, trial_d2);
      if (trial_potential < best_potential) {
        best_potential = trial_potential;
        best_centre = candidate;
        best_d2.swap(trial_d2);
      }
    }
    centres.push_back(best_centre);
    d2.swap(best_d2);
    potential = best_potential;
  }
  return centres;
}

}  // namespace

std::vector<Eigen::Vector3f> kmeans_pp_centres(std::span<const Float3> points, int clusters, std::mt19937_64& rng,
                                               int trials, std::size_t max_points) {
  check_clusters(static_cast<std::size_t>(clusters));
  return seed_centres(seed_points(points, max_points), clusters, rng, trials);
}

KMeansResult kmeans(KMeansEngine& engine, std::span<const Float3> points, const KMeansOptions& options, int attempts,
                    std::mt19937_64& rng) {
  engine.set_points(points);
  const SeedPoints seeds = seed_points(points, kKMeansPpMaxPoints);
  KMeansResult best;
  for (int attempt = 0; attempt < std::max(1, attempts); ++attempt) {
    KMeansResult r = lloyd(engine, seed_centres(seeds, options.clusters, rng, kKMeansPpTrials), options);
    if (attempt == 0 || r.compactness < best.compactness) best = std::move(r);
  }
  return best;
}

KMeansResult KMeansTracker::run(KMeansEngine& engine, std::span<const Float3> points) {
  return run(engine, points, points.size());
}

KMeansResult KMeansTracker::run(KMeansEngine& engine, std::span<const Float3> points, std::size_t clustered) {
  last_warm_ = last_random_ = false;
  KMeansResult best;
  if (clustered == 0 || clustered > points.size()) clustered = points.size();
  if (points.empty()) {
    best.centres.assign(static_cast<std::size_t>(options_.clusters), Eigen::Vector3f::Zero());
    best.converged = true;
    ++frame_;
    return best;
  }
  const std::span<const Float3> fit = points.first(clustered);
  engine.set_points(points);
  engine.use_first(clustered);
  bool have = false;
  if (previous_ && static_cast<int>(previous_->size()) == options_.clusters) {
    best = lloyd(engine, *previous_, options_);
    have = true;
    last_warm_ = true;
  }
  if (!have || !best.converged || (random_every_ > 0 && frame_ % random_every_ == 0)) {
    KMeansResult fresh = lloyd(engine, kmeans_pp_centres(fit, options_.clusters, rng_), options_);
    last_random_ = true;
    if (!have || fresh.compactness < best.compactness) best = std::move(fresh);
  }
  double variance = assign_all(engine, points, clustered, best);
  separate_merged_centres(engine, points, clustered, best, variance);
  previous_ = best.centres;
  ++frame_;
  return best;
}

double KMeansTracker::assign_all(KMeansEngine& engine, std::span<const Float3> points, std::size_t clustered,
                                 KMeansResult& result) const {
  if (clustered == points.size()) return result.compactness;
  engine.use_first(points.size());
  const double variance = engine.step(result.centres).total_variance();
  engine.read_labels(result.labels);
  return variance;
}

void KMeansTracker::separate_merged_centres(KMeansEngine& engine, std::span<const Float3> points,
                                            std::size_t clustered, KMeansResult& result, double variance) const {
  const auto squared = [](const Eigen::Vector3f& a, const Float3& p) {
    const float dx = p.x - a.x(), dy = p.y - a.y(), dz = p.z - a.z();
    return dx * dx + dy * dy + dz * dz;
  };
  const double merge2 = static_cast<double>(options_.merge_distance) * options_.merge_distance;
  for (int round = 0; round + 1 < options_.clusters; ++round) {
    // The closest pair of centres; nothing to do when every pair is farther than merge_distance.
    std::size_t a = 0, b = 0;
    double closest = merge2;
    for (std::size_t i = 0; i < result.centres.size(); ++i) {
      for (std::size_t j = i + 1; j < result.centres.size(); ++j) {
        const double d = (result.centres[i] - result.centres[j]).squaredNorm();
        if (d < closest) {
          closest = d;
          a = i;
          b = j;
        }
      }
    }
    if (a == b) return;
    // b moves to the point worst represented by its centre (among all points: a material seen
    // only where the clustering leaves pixels out still gets its centre).
    std::size_t farthest = 0;
    float worst = -1.f;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const float d = squared(result.centres[result.labels[i]], points[i]);
      if (d > worst) {
        worst = d;
        farthest = i;
      }
    }
    std::vector<Eigen::Vector3f> centres = result.centres;
    centres[b] = Eigen::Vector3f(points[farthest].x, points[farthest].y, points[farthest].z);
    engine.use_first(clustered);
    KMeansResult moved = lloyd(engine, std::move(centres), options_);
    const double moved_variance = assign_all(engine, points, clustered, moved);
    if (!(moved_variance < variance)) return;
    result = std::move(moved);
    variance = moved_variance;
  }
}

double adjusted_rand_index(std::span<const int> a, std::span<const int> b) {
  if (a.size() != b.size()) throw Error("adjusted_rand_index: labelings of different length");
  std::map<std::pair<int, int>, std::int64_t> table;
  std::map<int, std::int64_t> rows, cols;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ++table[{a[i], b[i]}];
    ++rows[a[i]];
    ++cols[b[i]];
  }
  auto pairs = [](std::int64_t n) { return static_cast<double>(n) * static_cast<double>(n - 1) / 2.0; };
  double index = 0.0, sum_rows = 0.0, sum_cols = 0.0;
  for (const auto& [key, n] : table) index += pairs(n);
  for (const auto& [key, n] : rows) sum_rows += pairs(n);
  for (const auto& [key, n] : cols) sum_cols += pairs(n);
  const double total = pairs(static_cast<std::int64_t>(a.size()));
  if (total == 0.0) return 1.0;
  const double expected = sum_rows * sum_cols / total;
  const double maximum = 0.5 * (sum_rows + sum_cols);
  if (maximum == expected) return 1.0;
  return (index - expected) / (maximum - expected);
}

}  // namespace relight::brdf
