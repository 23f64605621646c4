#pragma once
// Sample-based colour mapping (Knecht §4.5.2). All colours are display-referred linear sRGB in
// [0, 1]: the renderer's side is TM(L_r), TM(L_rv) (tone_map.h), the camera's side is the 8-bit
// camera image decoded with the sRGB curve.
//
// 1. Samples: `samples` pixels evenly spread over the virtual object (L_rv != L_r), colour c_a.
// 2. Matching (eqs. 4.20-4.22): for each sample the real pixel b of TM(L_r) maximising
//      match = h_m / (1 + |c_a - c_b|),  h_m = 0.5 - min(dh, 1 - dh),  dh = |h(c_a) - h(c_b)|
//    with h the HSV hue in [0, 1) and |.| the Euclidean RGB distance. Only every `grid_step`-th
//    pixel in x and y is searched (a subsampled grid), and only pixels valid as in
//    statistics_transfer.h (no virtual object, not black).
// 3. Pairs <C_r, C_cam> = <TM(L_r)(b), L_cam(b)>. The channel-swap heuristic adds, for each pair,
//    the 5 channel permutations (GRB, ...) of both colours, covering hues the scene lacks when
//    the camera transform treats channels alike.
// 4. Fit tau_sb by linear least squares (Eigen), one of three polynomial models (eqs. 4.23-4.26):
//      PerChannelAffine  c'_k = a0_k + a1_k c_k                  (6 coefficients)
//      Linear3x3         c'   = M c                              (9)
//      Affine3x4         c'   = M c + t                          (12)
//    with a tiny ridge term (1e-4 * ||A - identity||^2) so that rank-deficient pair sets (one
//    hue only) stay well-posed; it does not measurably move well-posed fits.
// 5. Exponential smoothing across frames (eq. 4.27): A = u A_new + (1 - u) A_prev, u = 0.3.
// Then delta_L = tau_sb(TM(L_rv)) - tau_sb(TM(L_r)) and L_final = L_cam + delta_L (eqs. 4.18-4.19).
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "relight/colormap/tone_map.h"
#include "relight/core/image.h"
#include "relight/core/named_values.h"

namespace relight::colormap {

enum class PolynomialModel { PerChannelAffine, Linear3x3, Affine3x4 };
inline constexpr std::array<NamedValue<PolynomialModel>, 3> kPolynomialModelNames{
    {{"per_channel_affine", PolynomialModel::PerChannelAffine},
     {"linear_3x3", PolynomialModel::Linear3x3},
     {"affine_3x4", PolynomialModel::Affine3x4}}};
[[nodiscard]] inline const char* to_string(PolynomialModel model) { return name_of(kPolynomialModelNames, model); }

struct SampleMappingOptions {
  int samples = 64;    ///< N virtual-object samples per frame
  int grid_step = 4;   ///< search every grid_step-th real pixel in x and y
  bool channel_swap = false;
  PolynomialModel model = PolynomialModel::Affine3x4;
  double smoothing = 0.3;  ///< u of eq. 4.27; 1 = no smoothing
  ToneMap tone_map{};
};

/// c' = A * (c, 1): columns 0-2 the 3x3 part, column 3 the offset.
using ColorMatrix = Eigen::Matrix<double, 3, 4>;
[[nodiscard]] ColorMatrix identity_color_matrix();

struct ColorPair {
  Eigen::Vector3d rendered;  ///< TM(L_r) at the matched pixel
  Eigen::Vector3d camera;    ///< decoded L_cam at the same pixel
};

/// HSV hue in [0, 1); 0 for greys.
[[nodiscard]] double hue(const Eigen::Vector3d& rgb);
/// Eq. 4.20-4.22.
[[nodiscard]] double hue_match(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// Steps 1-3. Empty when there is no virtual pixel or no valid real pixel.
[[nodiscard]] std::vector<ColorPair> find_color_pairs(const RadianceImage& real, const RadianceImage& real_virtual,
                                                      const ColorImage& camera, const SampleMappingOptions& options);
/// Step 4. Fewer pairs than coefficients per channel still gives a (ridge-regularised) answer.
[[nodiscard]] ColorMatrix fit_color_mapping(const std::vector<ColorPair>& pairs, PolynomialModel model);

[[nodiscard]] inline Eigen::Vector3d apply(const ColorMatrix& a, const Eigen::Vector3d& c) {
  return a.leftCols<3>() * c + a.col(3);
}

/// delta_L = tau_sb(TM(L_rv)) - tau_sb(TM(L_r)); exactly 0 where L_rv == L_r. Resizes `delta`.
void sample_delta(const RadianceImage& real, const RadianceImage& real_virtual, const ColorMatrix& mapping,
                  const ToneMap& tm, RadianceImage& delta);

/// Steps 1-5 frame after frame: keeps the smoothed coefficients between calls.
class SampleColorMapper {
 public:
  explicit SampleColorMapper(SampleMappingOptions options = {}) : options_(options) {}
  /// Fits this frame's pairs, smooths, writes delta; returns the smoothed coefficients. A frame
  /// without pairs keeps the previous coefficients (identity before the first fit).
  const ColorMatrix& map(const RadianceImage& real, const RadianceImage& real_virtual, const ColorImage& camera,
                         RadianceImage& delta);
  [[nodiscard]] const ColorMatrix& coefficients() const { return coefficients_; }
  [[nodiscard]] const SampleMappingOptions& options() const { return options_; }
  /// The operator of the next frames (the pipeline's changes every frame, tone_map_stage.h).
  void set_tone_map(const ToneMap& tm) { options_.tone_map = tm; }
  void reset() { fitted_ = false; coefficients_ = identity_color_matrix(); }

 private:
  SampleMappingOptions options_;
  ColorMatrix coefficients_ = identity_color_matrix();
  bool fitted_ = false;
};

}  // namespace relight::colormap
