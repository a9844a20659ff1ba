#include "boundary/boundary.hpp"

#include "core/parallel.hpp"

namespace aortasph {

void boundary_from_fluid(Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                         const FluidParams& ref) {
  const auto& idx = nb.index();
  parallel_for_dynamic(P.size(), [&](std::size_t w) {
    if (fluid_like(P.kind[w])) return;  // fluid, and open-boundary buffers (sim/boundary/open_boundary.hpp)
    double sum_w = 0.0, sum_pw = 0.0;
    Vec3 sum_rho_x = Vec3::Zero(), sum_v = Vec3::Zero();
    for (uint32_t k = nb.begin(w); k < nb.end(w); ++k) {
      const uint32_t f = idx[k];
      if (!fluid_like(P.kind[f])) continue;
      const Vec3 xwf = ctx.separation(P.x[w], P.x[f]);
      const double W = ctx.kernel.W(xwf.norm());
      sum_w += W;
      sum_pw += P.p[f] * W;
      sum_rho_x += (P.rho[f] * W) * xwf;
      sum_v += W * P.v[f];
    }
    if (sum_w <= 0.0) {
      // No fluid nearby: the particle takes no part in any fluid sum this step.
      P.p[w] = 0.0;
      P.rho[w] = ref.rho0;
      P.v_wall[w] = P.v[w];
      return;
    }
    // eq. (27); the moving wall's acceleration a_w enters here. Negative wall pressure is cut to zero so a
    // free surface touching a wall does not glue the fluid to it (a common practice, e.g. SPHinXsys); zero
    // as the momentum equation measures it, from the gauge (ctx.gauge, docs/model.md "Pressure gauge").
    const double p = (sum_pw + (ctx.gravity - P.a[w]).dot(sum_rho_x)) / sum_w;
    P.p[w] = std::max(p, ctx.gauge);
    P.rho[w] = ref.density(P.p[w]);
    // eq. (22): mirrored fluid velocity for the no-slip viscous term.
    P.v_wall[w] = 2.0 * P.v[w] - sum_v / sum_w;
  });
}

}  // namespace aortasph
