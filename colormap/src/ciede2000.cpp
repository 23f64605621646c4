// CIEDE2000 after Sharma, Wu & Dalal (2005); equation numbers in comments are the paper's.
#include "relight/colormap/ciede2000.h"

#include <cmath>
#include <numbers>

namespace relight::colormap {

namespace {

constexpr double kPi = std::numbers::pi;
double degrees(double radians) { return radians * 180.0 / kPi; }
double radians(double degrees) { return degrees * kPi / 180.0; }

// Hue angle in [0, 360); 0 for a zero-chroma colour (eq. 4).
double hue_degrees(double a, double b) {
  if (a == 0.0 && b == 0.0) return 0.0;
  const double h = degrees(std::atan2(b, a));
  return h < 0.0 ? h + 360.0 : h;
}

}  // namespace

double ciede2000(const Lab& first, const Lab& second) {
  // Eqs. 2-5: a* stretched by G so that near-neutral colours get their proper chroma.
  const double c1 = std::hypot(first.a, first.b), c2 = std::hypot(second.a, second.b);
  const double c_mean7 = std::pow(0.5 * (c1 + c2), 7.0);
  const double g = 0.5 * (1.0 - std::sqrt(c_mean7 / (c_mean7 + std::pow(25.0, 7.0))));
  const double a1 = (1.0 + g) * first.a, a2 = (1.0 + g) * second.a;
  const double cp1 = std::hypot(a1, first.b), cp2 = std::hypot(a2, second.b);
  const double hp1 = hue_degrees(a1, first.b), hp2 = hue_degrees(a2, second.b);

  // Eqs. 8-10: differences; the hue difference is the short way round, 0 if a chroma is 0.
  const double dl = second.L - first.L;
  const double dc = cp2 - cp1;
  double dh = 0.0;
  if (cp1 * cp2 != 0.0) {
    dh = hp2 - hp1;
    if (dh > 180.0) dh -= 360.0;
    if (dh < -180.0) dh += 360.0;
  }
  const double d_big_h = 2.0 * std::sqrt(cp1 * cp2) * std::sin(radians(dh / 2.0));

  // Eqs. 12-14: means; the hue mean is taken across the 0/360 seam when the hues are far apart.
  const double l_mean = 0.5 * (first.L + second.L);
  const double cp_mean = 0.5 * (cp1 + cp2);
  double hp_mean = hp1 + hp2;
  if (cp1 * cp2 != 0.0) {
    if (std::fabs(hp1 - hp2) <= 180.0) {
      hp_mean = 0.5 * (hp1 + hp2);
    } else {
      hp_mean = (hp1 + hp2 < 360.0) ? 0.5 * (hp1 + hp2 + 360.0) : 0.5 * (hp1 + hp2 - 360.0);
    }
  }

  // Eqs. 15-22: weighting functions and the rotation term.
  const double t = 1.0 - 0.17 * std::cos(radians(hp_mean - 30.0)) + 0.24 * std::cos(radians(2.0 * hp_mean)) +
                   0.32 * std::cos(radians(3.0 * hp_mean + 6.0)) - 0.20 * std::cos(radians(4.0 * hp_mean - 63.0));
  const double d_theta = 30.0 * std::exp(-std::pow((hp_mean - 275.0) / 25.0, 2.0));
  const double cp_mean7 = std::pow(cp_mean, 7.0);
  const double rc = 2.0 * std::sqrt(cp_mean7 / (cp_mean7 + std::pow(25.0, 7.0)));
  const double l50 = (l_mean - 50.0) * (l_mean - 50.0);
  const double sl = 1.0 + 0.015 * l50 / std::sqrt(20.0 + l50);
  const double sc = 1.0 + 0.045 * cp_mean;
  const double sh = 1.0 + 0.015 * cp_mean * t;
  const double rt = -std::sin(radians(2.0 * d_theta)) * rc;

  const double tl = dl / sl, tc = dc / sc, th = d_big_h / sh;
  return std::sqrt(tl * tl + tc * tc + th * th + rt * tc * th);
}

}  // namespace relight::colormap
