#include "fluid/shifting.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

namespace aortasph {

void fluid_shifting(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx, double dx,
                    double dt, std::vector<Vec3>& shift) {
  shift.assign(P.size(), Vec3::Zero());
  const auto& idx = nb.index();
  const CubicSpline& K = ctx.kernel;
  const double support2 = K.support * K.support;
  const double w_dx = K.W(dx);
  constexpr double R = 0.2;
  const double cap = 0.1 * dx;
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid) return;
    const double A = ctx.params[P.material[i]].shifting;
    if (A <= 0.0) return;
    const Vec3 xi = P.x[i];
    Vec3 grad_c = Vec3::Zero();
    double div_r = 0.0;
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      const Vec3 xij = ctx.separation(xi, P.x[j]);
      const double r2 = xij.squaredNorm();
      if (r2 >= support2 || r2 <= 0.0) continue;
      const double r = std::sqrt(r2);
      const Vec3 grad_w = (K.dWdr(r) / r) * xij;
      const double vj = P.m[j] / P.rho[j];
      const double q = K.W(r) / w_dx;
      grad_c += (vj * (1.0 + R * q * q * q * q)) * grad_w;
      div_r -= vj * grad_w.dot(xij);
    }
    if (div_r < 1.5) return;  // a splash: too few neighbours to tell disorder from emptiness
    Vec3 dr = -(A * K.h * P.v[i].norm() * dt) * grad_c;
    if (div_r < 2.5) {  // at the free surface: along it only
      const double g = grad_c.norm();
      if (g <= 0.0) return;
      const Vec3 n = -grad_c / g;
      dr -= dr.dot(n) * n;
    }
    const double len = dr.norm();
    shift[i] = len > cap ? Vec3(dr * (cap / len)) : dr;
  });
}

}  // namespace aortasph
