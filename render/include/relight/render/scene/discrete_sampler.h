#pragma once
// Picking one of several items in proportion to a weight (a discrete distribution by its
// cumulative sums): the sources of the multiple-bounce light source (vpl.h) and the VPLs that
// shoot caustic photons (dir/caustic_photons.h).
#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace relight::render {

class DiscreteSampler {
 public:
  /// Adds item `index` with `weight`; items of weight <= 0 (or NaN) are left out.
  void add(std::size_t index, double weight) {
    if (!(weight > 0.0)) return;
    total_ += weight;
    indices_.push_back(index);
    cumulative_.push_back(total_);
  }
  [[nodiscard]] std::size_t size() const { return indices_.size(); }
  [[nodiscard]] double total() const { return total_; }
  /// The item at u in [0, 1) and the probability it had; size() must be > 0.
  [[nodiscard]] std::pair<std::size_t, double> pick(double u) const {
    const auto found = static_cast<std::size_t>(std::upper_bound(cumulative_.begin(), cumulative_.end(), u * total_) -
                                                cumulative_.begin());
    const std::size_t k = std::min(found, indices_.size() - 1);
    return {indices_[k], (cumulative_[k] - (k > 0 ? cumulative_[k - 1] : 0.0)) / total_};
  }

 private:
  std::vector<std::size_t> indices_;
  std::vector<double> cumulative_;
  double total_ = 0.0;
};

}  // namespace relight::render
