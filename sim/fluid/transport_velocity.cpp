#include "fluid/transport_velocity.hpp"

#include <cmath>

#include "core/parallel.hpp"

namespace aortasph {

void fluid_transport_velocity(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                              double dt, std::vector<Vec3>& dv) {
  dv.assign(P.size(), Vec3::Zero());
  const auto& idx = nb.index();
  const CubicSpline& K = ctx.kernel;
  const double support2 = K.support * K.support;
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid) return;
    const double pb = ctx.params[P.material[i]].tv_pb;
    if (pb <= 0.0) return;
    const Vec3 xi = P.x[i];
    const double vi2 = ctx.volume[i] * ctx.volume[i];
    Vec3 sum = Vec3::Zero();  // sum_j (V_i^2 + V_j^2) grad_i W_ij
    double div_r = 0.0;
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      const Vec3 xij = ctx.separation(xi, P.x[j]);
      const double r2 = xij.squaredNorm();
      if (r2 >= support2 || r2 <= 0.0) continue;  // Verlet-list pairs in the skin
      if (P.kind[j] == Kind::Shell) return;       // beside a shell: off (see the header)
      const double r = std::sqrt(r2);
      const Vec3 grad_w = (K.dWdr(r) / r) * xij;
      const double vj = ctx.volume[j];
      sum += (vi2 + vj * vj) * grad_w;
      div_r -= vj * grad_w.dot(xij);
    }
    if (div_r < 2.5) return;  // at a free surface: off (see the header)
    dv[i] = (-0.5 * dt * pb / P.m[i]) * sum;
  });
}

}  // namespace aortasph
