#include "relight/brdf/highlight.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "relight/core/parallel.h"

namespace relight::brdf {

bool is_highlight(Rgb8 color, const HighlightOptions& options) {
  // I >= I_min and S <= S_max without divisions: sum >= 765 I_min and 3 min >= (1 - S_max) sum.
  const int sum = color.r + color.g + color.b;
  if (sum == 0) return false;
  const int lowest = std::min({color.r, color.g, color.b});
  return static_cast<float>(sum) >= options.intensity_min * 765.f &&
         static_cast<float>(3 * lowest) >= (1.f - options.saturation_max) * static_cast<float>(sum);
}

void dilate_disk(const Mask& input, int radius, Mask& output, int threads) {
  const int w = input.width(), h = input.height();
  output.resize(w, h);
  if (radius <= 0) {
    output = input;
    return;
  }
  // Per row, the horizontal distance to the nearest set pixel (capped at radius + 1); a pixel is
  // set in the output when some row dy away holds a set pixel within sqrt(r^2 - dy^2) columns.
  const int far = radius + 1;
  // Rows without a set pixel within `radius` rows stay empty: highlights are rare, so most of
  // the image is skipped.
  std::vector<std::uint8_t> row_set(static_cast<std::size_t>(h), 0), row_near(static_cast<std::size_t>(h), 0);
  parallel_for_each_row(h, threads, [&](int r) {
    const auto row = input.row(r);
    row_set[static_cast<std::size_t>(r)] = std::any_of(row.begin(), row.end(), [](std::uint8_t v) { return v != 0; });
  });
  for (int r = 0; r < h; ++r) {
    if (!row_set[static_cast<std::size_t>(r)]) continue;
    for (int rr = std::max(0, r - radius); rr <= std::min(h - 1, r + radius); ++rr) row_near[static_cast<std::size_t>(rr)] = 1;
  }
  std::vector<std::uint8_t> distance(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  parallel_for_each_row(h, threads, [&](int r) {
    std::uint8_t* d = distance.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(w);
    if (!row_set[static_cast<std::size_t>(r)]) {
      std::fill(d, d + w, static_cast<std::uint8_t>(far));
      return;
    }
    int last = -far - 1;
    for (int c = 0; c < w; ++c) {
      if (input(r, c)) last = c;
      d[c] = static_cast<std::uint8_t>(std::min(far, c - last));
    }
    last = std::numeric_limits<int>::max() / 2;
    for (int c = w - 1; c >= 0; --c) {
      if (input(r, c)) last = c;
      d[c] = static_cast<std::uint8_t>(std::min<int>(d[c], std::min(far, last - c)));
    }
  });
  std::vector<int> reach(static_cast<std::size_t>(radius) + 1);
  for (int dy = 0; dy <= radius; ++dy) {
    reach[static_cast<std::size_t>(dy)] = static_cast<int>(std::floor(std::sqrt(static_cast<double>(radius * radius - dy * dy))));
  }
  parallel_for_each_row(h, threads, [&](int r) {
    if (!row_near[static_cast<std::size_t>(r)]) {
      const auto row = output.row(r);
      std::fill(row.begin(), row.end(), std::uint8_t{0});
      return;
    }
    for (int c = 0; c < w; ++c) {
      std::uint8_t on = 0;
      for (int dy = -radius; dy <= radius && !on; ++dy) {
        const int rr = r + dy;
        if (rr < 0 || rr >= h) continue;
        const int d = distance[static_cast<std::size_t>(rr) * static_cast<std::size_t>(w) + static_cast<std::size_t>(c)];
        on = d <= reach[static_cast<std::size_t>(std::abs(dy))] ? 1 : 0;
      }
      output(r, c) = on;
    }
  });
}

namespace {

/// Chebyshev (chessboard) distance of every pixel to the nearest pixel outside `mask`, 0 outside
/// it, `unreachable` where no such pixel is that near: two raster sweeps of the 3 x 3 chamfer
/// with unit weights, which is exact for this metric.
std::vector<int> chessboard_distance(const Mask& mask, int unreachable) {
  const int w = mask.width(), h = mask.height();
  std::vector<int> d(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  const auto at = [&](int r, int c) -> int& {
    return d[static_cast<std::size_t>(r) * static_cast<std::size_t>(w) + static_cast<std::size_t>(c)];
  };
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      int v = mask(r, c) ? unreachable : 0;
      if (v != 0) {
        if (c > 0) v = std::min(v, at(r, c - 1) + 1);
        if (r > 0) {
          for (int cc = std::max(0, c - 1); cc <= std::min(w - 1, c + 1); ++cc) v = std::min(v, at(r - 1, cc) + 1);
        }
      }
      at(r, c) = v;
    }
  for (int r = h - 1; r >= 0; --r)
    for (int c = w - 1; c >= 0; --c) {
      int v = at(r, c);
      if (v == 0) continue;
      if (c + 1 < w) v = std::min(v, at(r, c + 1) + 1);
      if (r + 1 < h) {
        for (int cc = std::max(0, c - 1); cc <= std::min(w - 1, c + 1); ++cc) v = std::min(v, at(r + 1, cc) + 1);
      }
      at(r, c) = v;
    }
  return d;
}

}  // namespace

void remove_highlights(const ColorImage& color, const HighlightOptions& options, ColorImage& cleaned, Mask& mask) {
  const int w = color.width(), h = color.height();
  Mask seeds(w, h);
  parallel_for_each_row(h, options.threads, [&](int r) {
    for (int c = 0; c < w; ++c) seeds(r, c) = is_highlight(color(r, c), options) ? 1 : 0;
  });
  dilate_disk(seeds, options.dilate_radius, mask, options.threads);
  cleaned = color;
  // The ring of the nearest unmasked pixels is the one at their Chebyshev distance: searched
  // alone, not after every smaller ring (a white desk under an overexposed camera is masked
  // over whole regions, where searching ring after ring took 30-350 ms a frame at 640x480).
  const int unreachable = options.fill_radius_max + 1;
  const std::vector<int> ring_of = chessboard_distance(mask, unreachable);
  parallel_for_each_row(h, options.threads, [&](int r) {
    for (int c = 0; c < w; ++c) {
      const int ring = ring_of[static_cast<std::size_t>(r) * static_cast<std::size_t>(w) + static_cast<std::size_t>(c)];
      if (ring == 0 || ring >= unreachable) continue;
      // The nearest unmasked pixel of the ring by Euclidean distance, the first in row-major order on ties.
      int best = std::numeric_limits<int>::max();
      Rgb8 best_color{};
      const int r0 = std::max(0, r - ring), r1 = std::min(h - 1, r + ring);
      for (int rr = r0; rr <= r1; ++rr) {
        const bool edge_row = rr == r - ring || rr == r + ring;
        const int step = edge_row ? 1 : 2 * ring;
        for (int cc = c - ring; cc <= c + ring; cc += step) {
          if (cc < 0 || cc >= w || mask(rr, cc)) continue;
          const int d2 = (rr - r) * (rr - r) + (cc - c) * (cc - c);
          if (d2 < best) {
            best = d2;
            best_color = color(rr, cc);
          }
        }
      }
      cleaned(r, c) = best_color;
    }
  });
}

}  // namespace relight::brdf
