// K-means CPU engine, the shared Lloyd loop, seeding and the per-frame policy (kmeans.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include "relight/brdf/brdf_shared.h"
#include "relight/brdf/kmeans.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::brdf {

namespace {

constexpr float kValueScale = static_cast<float>(RELIGHT_KMEANS_VALUE_SCALE);
constexpr float kDistanceScale = static_cast<float>(RELIGHT_KMEANS_DISTANCE_SCALE);
constexpr std::size_t kChunk = 8192;

void check_clusters(std::size_t clusters) {
  if (clusters < 1 || clusters > RELIGHT_KMEANS_MAX_CLUSTERS) {
    throw Error("brdf K-means: the number of clusters must be 1.." + std::to_string(RELIGHT_KMEANS_MAX_CLUSTERS));
  }
}

// The same float expressions as brdf_kmeans.comp (no contraction: this file is built with
// -ffp-contract=off).
inline std::uint32_t quantise(float value, float scale) { return static_cast<std::uint32_t>(value * scale + 0.5f); }

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

struct KMeansCpu::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

KMeansCpu::KMeansCpu(int threads) : threads_(threads) {}
KMeansCpu::~KMeansCpu() = default;
KMeansCpu::KMeansCpu(KMeansCpu&&) noexcept = default;
KMeansCpu& KMeansCpu::operator=(KMeansCpu&&) noexcept = default;

void KMeansCpu::set_points(std::span<const Float3> points) {
  const std::size_t n = points.size();
  xs_.resize(n);
  ys_.resize(n);
  zs_.resize(n);
  qx_.resize(n);
  qy_.resize(n);
  qz_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    xs_[i] = points[i].x;
    ys_[i] = points[i].y;
    zs_[i] = points[i].z;
    qx_[i] = quantise(points[i].x, kValueScale);
    qy_[i] = quantise(points[i].y, kValueScale);
    qz_[i] = quantise(points[i].z, kValueScale);
  }
  active_ = n;
}

namespace {

constexpr int kBlock = 256;

/// Nearest centre of `count` points (structure of arrays) and the quantised squared distance;
/// written as plain loops over the points so that GCC vectorises them, and also built for AVX2
/// ("avx2" does not enable FMA: both versions round exactly like the shader).
__attribute__((target_clones("avx2", "default"))) void assign_block(
    const float* x, const float* y, const float* z, int count, const float* cx, const float* cy, const float* cz,
    int clusters, std::uint8_t* label, std::uint32_t* distance) {
  // The running argmin in 32-bit lanes like the distances, so that the selects vectorise
  // without packing masks to bytes.
  float best[kBlock];
  std::int32_t arg[kBlock];
  for (int i = 0; i < count; ++i) {
    best[i] = std::numeric_limits<float>::infinity();
    arg[i] = 0;
  }
  for (int k = 0; k < clusters; ++k) {
    const float ax = cx[k], ay = cy[k], az = cz[k];
    const std::int32_t kk = k;
    for (int i = 0; i < count; ++i) {
      const float dx = x[i] - ax, dy = y[i] - ay, dz = z[i] - az;
      const float d = (dx * dx + dy * dy) + dz * dz;
      const bool closer = d < best[i];
      best[i] = closer ? d : best[i];
      arg[i] = closer ? kk : arg[i];
    }
  }
  for (int i = 0; i < count; ++i) {
    label[i] = static_cast<std::uint8_t>(arg[i]);
    distance[i] = static_cast<std::uint32_t>(best[i] * kDistanceScale + 0.5f);
  }
}

/// Adds the block's per-cluster sums to `sums`: for each cluster a masked reduction over the
/// block in 32-bit integers (a block's sums fit, brdf_shared.h), which vectorises, instead of a
/// scatter into the cluster's sums per point, whose additions wait on each other whenever
/// neighbouring points share a cluster. Integer sums: the same totals in any order.
__attribute__((target_clones("avx2", "default"))) void sum_block(
    const std::uint8_t* label, const std::uint32_t* qx, const std::uint32_t* qy, const std::uint32_t* qz,
    const std::uint32_t* distance, int count, int clusters, ClusterSums::Cluster* sums) {
  for (int k = 0; k < clusters; ++k) {
    const auto kk = static_cast<std::uint8_t>(k);
    std::uint32_t sx = 0, sy = 0, sz = 0, n = 0, sd = 0;
    for (int i = 0; i < count; ++i) {
      const std::uint32_t in = label[i] == kk ? 1u : 0u;
      const std::uint32_t mask = 0u - in;
      sx += qx[i] & mask;
      sy += qy[i] & mask;
      sz += qz[i] & mask;
      sd += distance[i] & mask;
      n += in;
    }
    ClusterSums::Cluster& s = sums[k];
    s.sum[0] += sx;
    s.sum[1] += sy;
    s.sum[2] += sz;
    s.count += n;
    s.distance += sd;
  }
}

}  // namespace

ClusterSums KMeansCpu::step(std::span<const Eigen::Vector3f> centres) {
  const std::size_t k_count = centres.size();
  check_clusters(k_count);
  const std::size_t n = active_;
  labels_.resize(n);
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<ClusterSums::Cluster> partial(chunks * k_count);
  float cx[RELIGHT_KMEANS_MAX_CLUSTERS], cy[RELIGHT_KMEANS_MAX_CLUSTERS], cz[RELIGHT_KMEANS_MAX_CLUSTERS];
  for (std::size_t k = 0; k < k_count; ++k) {
    cx[k] = centres[k].x();
    cy[k] = centres[k].y();
    cz[k] = centres[k].z();
  }
  // TBB rather than parallel_rows(): its workers stay alive between the 20-100 steps of a run,
  // and a chunk that no worker has taken yet runs on the calling thread instead of waiting for a
  // helper thread to be scheduled (on a loaded machine that wait cost more than the step).
  const auto run_chunks = [&](int begin, int end) {
        std::uint32_t distance[kBlock];
        for (int chunk = begin; chunk < end; ++chunk) {
          ClusterSums::Cluster* sums = partial.data() + static_cast<std::size_t>(chunk) * k_count;
          const std::size_t first = static_cast<std::size_t>(chunk) * kChunk;
          const std::size_t last = std::min(n, first + kChunk);
          for (std::size_t b = first; b < last; b += kBlock) {
            const int count = static_cast<int>(std::min<std::size_t>(kBlock, last - b));
            std::uint8_t* label = labels_.data() + b;
            assign_block(xs_.data() + b, ys_.data() + b, zs_.data() + b, count, cx, cy, cz, static_cast<int>(k_count),
                         label, distance);
            sum_block(label, qx_.data() + b, qy_.data() + b, qz_.data() + b, distance, count,
                      static_cast<int>(k_count), sums);
          }
        }
  };
  if (worker_count(threads_) <= 1 || chunks <= 1) {
    run_chunks(0, static_cast<int>(chunks));
  } else {
    if (!arena_) arena_ = std::make_unique<Arena>(worker_count(threads_));
    arena_->arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(chunks), 1),
                        [&](const tbb::blocked_range<int>& range) { run_chunks(range.begin(), range.end()); });
    });
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

std::vector<Eigen::Vector3f> kmeans_pp_centres(std::span<const Float3> all_points, int clusters, std::mt19937_64& rng,
                                               int trials, std::size_t max_points) {
  check_clusters(static_cast<std::size_t>(clusters));
  if (all_points.empty()) throw Error("brdf K-means: no points to seed from");
  // Seeding on an even-stride subset: the D^2 distribution of a few ten thousand points is the
  // same for seeding purposes and keeps the greedy trials cheap.
  std::vector<Float3> subset;
  std::span<const Float3> points = all_points;
  if (max_points > 0 && all_points.size() > max_points) {
    const std::size_t stride = (all_points.size() + max_points - 1) / max_points;
    for (std::size_t i = 0; i < all_points.size(); i += stride) subset.push_back(all_points[i]);
    points = subset;
  }
  const std::size_t n = points.size();
  auto distance2 = [](const Float3& p, const Eigen::Vector3f& c) {
    const float dx = p.x - c.x(), dy = p.y - c.y(), dz = p.z - c.z();
    return dx * dx + dy * dy + dz * dz;
  };
  std::vector<Eigen::Vector3f> centres;
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Float3 first = points[pick(rng)];
  centres.emplace_back(first.x, first.y, first.z);
  std::vector<float> d2(n), trial_d2(n), best_d2(n);
  double potential = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    d2[i] = distance2(points[i], centres[0]);
    potential += d2[i];
  }
  while (static_cast<int>(centres.size()) < clusters) {
    // Greedy k-means++ (as cv::kmeans and scikit-learn): `trials` candidates drawn by D^2, the
    // one that lowers the potential most wins.
    double best_potential = std::numeric_limits<double>::infinity();
    Eigen::Vector3f best_centre = centres.back();
    for (int t = 0; t < std::max(1, trials); ++t) {
      std::size_t chosen = pick(rng);
      if (potential > 0.0) {
        double target = unit(rng) * potential;
        for (std::size_t i = 0; i < n; ++i) {
          target -= d2[i];
          if (target <= 0.0) {
            chosen = i;
            break;
          }
        }
      }
      const Eigen::Vector3f candidate(points[chosen].x, points[chosen].y, points[chosen].z);
      double trial_potential = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        trial_d2[i] = std::min(d2[i], distance2(points[i], candidate));
        trial_potential += trial_d2[i];
      }
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

KMeansResult kmeans(KMeansEngine& engine, std::span<const Float3> points, const KMeansOptions& options, int attempts,
                    std::mt19937_64& rng) {
  engine.set_points(points);
  KMeansResult best;
  for (int attempt = 0; attempt < std::max(1, attempts); ++attempt) {
    KMeansResult r = lloyd(engine, kmeans_pp_centres(points, options.clusters, rng), options);
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
