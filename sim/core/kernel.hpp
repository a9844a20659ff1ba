// Cubic spline kernel, paper eq. (5) (Monaghan & Lattanzio 1985), support 2h, 3-D normalisation
// alpha = 3 / (2 pi h^3) so that the kernel integrates to one (eq. 6).
#pragma once

#include <cmath>
#include <numbers>

#include "scene.hpp"

namespace aortasph {

struct CubicSpline {
  double h = 1.0;
  double inv_h = 1.0;
  double alpha = 0.0;  // 3 / (2 pi h^3)
  double support = 2.0;

  explicit CubicSpline(double smoothing_length)
      : h(smoothing_length),
        inv_h(1.0 / smoothing_length),
        alpha(3.0 / (2.0 * std::numbers::pi * smoothing_length * smoothing_length * smoothing_length)),
        support(2.0 * smoothing_length) {}

  // W(q), q = r / h, eq. (5).
  double W(double r) const {
    const double q = r * inv_h;
    if (q < 1.0) return alpha * (2.0 / 3.0 - q * q + 0.5 * q * q * q);
    if (q < 2.0) {
      const double t = 2.0 - q;
      return alpha * (1.0 / 6.0) * t * t * t;
    }
    return 0.0;
  }

  // dW/dr = (dW/dq) / h.
  double dWdr(double r) const {
    const double q = r * inv_h;
    if (q < 1.0) return alpha * inv_h * (-2.0 * q + 1.5 * q * q);
    if (q < 2.0) {
      const double t = 2.0 - q;
      return -alpha * inv_h * 0.5 * t * t;
    }
    return 0.0;
  }

  // grad_i W(x_i - x_j) = dW/dr * x_ij / |x_ij| (text after eq. 10). Exactly antisymmetric in i, j
  // because x_ji = -x_ij bit for bit: pair forces built from it cancel exactly.
  Vec3 gradW(const Vec3& xij, double r) const {
    if (r <= 0.0) return Vec3::Zero();
    return (dWdr(r) / r) * xij;
  }
};

// The 2-D cubic spline (Monaghan & Lattanzio 1985), normalisation 10 / (7 pi h^2), support 2h: the patch
// weight of a sheet's particles over its tangent plane (shell contact, the fluid's thickness barrier).
inline double cubic_spline_2d(double r, double h) {
  const double q = r / h;
  const double alpha = 10.0 / (7.0 * std::numbers::pi * h * h);
  if (q < 1.0) return alpha * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
  if (q < 2.0) {
    const double t = 2.0 - q;
    return alpha * 0.25 * t * t * t;
  }
  return 0.0;
}

}  // namespace aortasph
