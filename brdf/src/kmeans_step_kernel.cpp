// The Lloyd step's inner loop (kmeans_step_kernel.h). Built with -ffp-contract=off: a fused
// multiply-add would round the distances differently from the shader.
#include "kmeans_step_kernel.h"

#include <immintrin.h>

#include <limits>

namespace relight::brdf::detail {

namespace {

constexpr float kValueScale = static_cast<float>(RELIGHT_KMEANS_VALUE_SCALE);
constexpr float kDistanceScale = static_cast<float>(RELIGHT_KMEANS_DISTANCE_SCALE);

inline std::uint32_t quantise(float value, float scale) { return static_cast<std::uint32_t>(value * scale + 0.5f); }

void assign_and_sum_portable(const float* x, const float* y, const float* z, std::size_t count,
                             const KMeansCentres& centres, std::uint8_t* labels, ClusterSums::Cluster* sums) {
  for (std::size_t i = 0; i < count; ++i) {
    float best = std::numeric_limits<float>::infinity();
    int label = 0;
    for (int k = 0; k < centres.count; ++k) {
      const float dx = x[i] - centres.x[k], dy = y[i] - centres.y[k], dz = z[i] - centres.z[k];
      const float d = (dx * dx + dy * dy) + dz * dz;
      if (d < best) {
        best = d;
        label = k;
      }
    }
    labels[i] = static_cast<std::uint8_t>(label);
    ClusterSums::Cluster& s = sums[label];
    s.sum[0] += quantise(x[i], kValueScale);
    s.sum[1] += quantise(y[i], kValueScale);
    s.sum[2] += quantise(z[i], kValueScale);
    s.count += 1;
    s.distance += quantise(best, kDistanceScale);
  }
}

// Per cluster, 8 lanes of 32-bit running sums (colour x, y, z, count, distance). A lane gains at
// most 2 * 2^22 (colour) or 12 * 2^20 (distance) per vector (brdf_shared.h), so 256 vectors fit
// in 32 bits; then the lanes go into the 64-bit sums.
constexpr int kVectorsPerFlush = 256;

struct alignas(32) LaneSums {
  __m256i lanes[RELIGHT_KMEANS_MAX_CLUSTERS][5];
};

__attribute__((target("avx2"))) void flush(LaneSums& acc, int clusters, ClusterSums::Cluster* sums) {
  alignas(32) std::uint32_t lane[8];
  for (int k = 0; k < clusters; ++k) {
    std::uint64_t total[5];
    for (int s = 0; s < 5; ++s) {
      _mm256_store_si256(reinterpret_cast<__m256i*>(lane), acc.lanes[k][s]);
      total[s] = 0;
      for (const std::uint32_t v : lane) total[s] += v;
      acc.lanes[k][s] = _mm256_setzero_si256();
    }
    sums[k].sum[0] += total[0];
    sums[k].sum[1] += total[1];
    sums[k].sum[2] += total[2];
    sums[k].count += total[3];
    sums[k].distance += total[4];
  }
}

/// N groups of eight points: their nearest centres (as 32-bit lanes) and the squared distances
/// to them. The groups are independent, so their compare-and-select chains over the centres
/// overlap in the pipeline instead of waiting on each other.
template <int N>
__attribute__((target("avx2"))) inline void nearest(const float* x, const float* y, const float* z,
                                                    const KMeansCentres& c, __m256i (&arg)[N], __m256 (&best)[N]) {
  __m256 px[N], py[N], pz[N];
  for (int j = 0; j < N; ++j) {
    px[j] = _mm256_loadu_ps(x + 8 * j);
    py[j] = _mm256_loadu_ps(y + 8 * j);
    pz[j] = _mm256_loadu_ps(z + 8 * j);
    best[j] = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    arg[j] = _mm256_setzero_si256();
  }
  for (int k = 0; k < c.count; ++k) {
    const __m256 cx = _mm256_set1_ps(c.x[k]), cy = _mm256_set1_ps(c.y[k]), cz = _mm256_set1_ps(c.z[k]);
    const __m256i label = _mm256_set1_epi32(k);
    for (int j = 0; j < N; ++j) {
      const __m256 dx = _mm256_sub_ps(px[j], cx), dy = _mm256_sub_ps(py[j], cy), dz = _mm256_sub_ps(pz[j], cz);
      const __m256 d =
          _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
      const __m256 closer = _mm256_cmp_ps(d, best[j], _CMP_LT_OQ);
      best[j] = _mm256_blendv_ps(best[j], d, closer);
      arg[j] = _mm256_blendv_epi8(arg[j], label, _mm256_castps_si256(closer));
    }
  }
}

/// value * scale + 0.5 truncated, for values in [0, 2^31) as here (the features are clamped).
__attribute__((target("avx2"))) inline __m256i quantise8(__m256 value, __m256 scale) {
  return _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(value, scale), _mm256_set1_ps(0.5f)));
}

__attribute__((target("avx2"))) void store_labels(__m256i arg, std::uint8_t* labels) {
  const __m128i words = _mm_packs_epi32(_mm256_castsi256_si128(arg), _mm256_extracti128_si256(arg, 1));
  _mm_storel_epi64(reinterpret_cast<__m128i*>(labels), _mm_packus_epi16(words, words));
}

/// Adds the lanes of (qx, qy, qz, 1, qd) where `in` is all ones to a cluster's lane sums.
__attribute__((target("avx2"))) inline void add_masked(__m256i* lane, __m256i in, __m256i qx, __m256i qy, __m256i qz,
                                                      __m256i qd) {
  lane[0] = _mm256_add_epi32(lane[0], _mm256_and_si256(in, qx));
  lane[1] = _mm256_add_epi32(lane[1], _mm256_and_si256(in, qy));
  lane[2] = _mm256_add_epi32(lane[2], _mm256_and_si256(in, qz));
  lane[3] = _mm256_sub_epi32(lane[3], in);
  lane[4] = _mm256_add_epi32(lane[4], _mm256_and_si256(in, qd));
}

__attribute__((target("avx2"))) void assign_and_sum_avx2(const float* x, const float* y, const float* z,
                                                         std::size_t count, const KMeansCentres& centres,
                                                         std::uint8_t* labels, ClusterSums::Cluster* sums) {
  LaneSums acc;
  for (int k = 0; k < centres.count; ++k) {
    for (__m256i& lane : acc.lanes[k]) lane = _mm256_setzero_si256();
  }
  const __m256 value_scale = _mm256_set1_ps(kValueScale), distance_scale = _mm256_set1_ps(kDistanceScale);
  const std::size_t vectors = count / 8;
  int pending = 0;
  const auto add = [&](std::size_t i, __m256i arg, __m256 best) __attribute__((target("avx2"))) {
    store_labels(arg, labels + i);
    const __m256i qx = quantise8(_mm256_loadu_ps(x + i), value_scale);
    const __m256i qy = quantise8(_mm256_loadu_ps(y + i), value_scale);
    const __m256i qz = quantise8(_mm256_loadu_ps(z + i), value_scale);
    const __m256i qd = quantise8(best, distance_scale);
    const int first_label = _mm256_cvtsi256_si32(arg);
    const __m256i same = _mm256_cmpeq_epi32(arg, _mm256_set1_epi32(first_label));
    if (_mm256_movemask_epi8(same) == -1) {
      // Neighbouring pixels mostly share a material: all eight points go to one cluster.
      add_masked(acc.lanes[first_label], same, qx, qy, qz, qd);
    } else {
      for (int k = 0; k < centres.count; ++k) {
        add_masked(acc.lanes[k], _mm256_cmpeq_epi32(arg, _mm256_set1_epi32(k)), qx, qy, qz, qd);
      }
    }
    if (++pending == kVectorsPerFlush) {
      flush(acc, centres.count, sums);
      pending = 0;
    }
  };
  std::size_t v = 0;
  for (; v + 2 <= vectors; v += 2) {
    __m256i arg[2];
    __m256 best[2];
    nearest<2>(x + 8 * v, y + 8 * v, z + 8 * v, centres, arg, best);
    add(8 * v, arg[0], best[0]);
    add(8 * v + 8, arg[1], best[1]);
  }
  for (; v < vectors; ++v) {
    __m256i arg[1];
    __m256 best[1];
    nearest<1>(x + 8 * v, y + 8 * v, z + 8 * v, centres, arg, best);
    add(8 * v, arg[0], best[0]);
  }
  flush(acc, centres.count, sums);
  const std::size_t done = vectors * 8;
  assign_and_sum_portable(x + done, y + done, z + done, count - done, centres, labels + done, sums);
}

}  // namespace

void kmeans_assign_and_sum(const float* x, const float* y, const float* z, std::size_t count,
                           const KMeansCentres& centres, std::uint8_t* labels, ClusterSums::Cluster* sums,
                           bool portable) {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && !portable) {
    assign_and_sum_avx2(x, y, z, count, centres, labels, sums);
  } else {
    assign_and_sum_portable(x, y, z, count, centres, labels, sums);
  }
}

}  // namespace relight::brdf::detail
