#include "fluid/shifting.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

namespace aortasph {

void add_shift_ghosts(ShiftSums& s, const Particles& P, const FluidContext& ctx, double w_dx, std::size_t i,
                      uint32_t j, const Vec3& xij) {
  const double support2 = ctx.kernel.support * ctx.kernel.support;
  const ShellWall& sw = *ctx.shell_wall;
  const double vg = sw.ghost_mass[j] / sw.ghost_rho;
  sw.for_each_ghost(xij, i, j, P.body[j], [&](const Vec3& rg) {
    const double rg2 = rg.squaredNorm();
    // Not a boundary to the wall rule (shifting.hpp): the sheet's own coupling keeps the fluid off it.
    if (rg2 < support2 && rg2 > 0.0) {
      s.add(ctx.kernel, w_dx, rg, rg2, vg, -1);
      s.near_sheet = true;
    }
  });
}

Vec3 shift_from(const ShiftSums& s, double A, double h, double speed, double dt, double dx) {
  if (s.div_r < 1.5) return Vec3::Zero();  // a splash: too few neighbours to tell disorder from emptiness
  Vec3 dr = -(A * h * speed * dt) * s.grad_c;
  if (s.div_r < 2.5) {  // at the free surface: along it only
    const double g = s.grad_c.norm();
    if (g <= 0.0) return Vec3::Zero();
    const Vec3 n = -s.grad_c / g;
    dr -= dr.dot(n) * n;
  }
  // Beside boundaries: never towards one. The bodies dr points towards (dr . n_k > 0, n_k the direction of
  // body k's share of sum V grad W) are the active ones; dr loses its part along the span of their normals
  // (orthonormalised by Gram-Schmidt; a normal within about 1 degree of the span of those before it adds
  // nothing), and bodies the remainder points towards join the set, until none does. A part away from a body
  // is kept: it is what holds a particle that came too close off the wall (the anti-clumping term of grad C).
  const Vec3 dr0 = dr;
  std::array<bool, ShiftSums::kBodies> active{};
  for (int pass = 0; pass < ShiftSums::kBodies; ++pass) {
    bool joined = false;
    for (int k = 0; k < s.boundaries; ++k)
      if (!active[k] && dr.dot(s.boundary[k]) > 1e-12 * dr.norm() * s.boundary[k].norm())
        active[k] = joined = true;
    if (!joined) break;
    std::array<Vec3, 3> basis;
    int nb = 0;
    for (int k = 0; k < s.boundaries && nb < 3; ++k) {
      if (!active[k]) continue;
      Vec3 n = s.boundary[k];
      const double len0 = n.norm();
      for (int m = 0; m < nb; ++m) n -= n.dot(basis[m]) * basis[m];
      const double len = n.norm();
      if (len > 0.02 * len0) basis[nb++] = n / len;
    }
    dr = dr0;
    for (int m = 0; m < nb; ++m) dr -= dr.dot(basis[m]) * basis[m];
  }
  const double cap = 0.1 * dx, len = dr.norm();
  return len > cap ? Vec3(dr * (cap / len)) : dr;
}

void fluid_shifting(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx, double dx,
                    double dt, std::vector<Vec3>& shift) {
  shift.assign(P.size(), Vec3::Zero());
  const auto& idx = nb.index();
  const CubicSpline& K = ctx.kernel;
  const double w_dx = K.W(dx);
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid) return;
    const double A = ctx.params[P.material[i]].shifting;
    if (A <= 0.0) return;
    const Vec3 xi = P.x[i];
    ShiftSums sums;
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      add_shift_neighbour(sums, P, ctx, w_dx, i, j, ctx.separation(xi, P.x[j]));
    }
    shift[i] = shift_at(sums, ctx.params[P.material[i]], K.h, P.v[i].norm(), dt, dx);
  });
}

}  // namespace aortasph
