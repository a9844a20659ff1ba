#include "fluid/fluid_wcsph.hpp"

#include <algorithm>

#include "core/parallel.hpp"
#include "fluid/shifting.hpp"

namespace aortasph {

namespace {

// The shell terms of the density loops (fluid/shell_wall.hpp), out of line: only scenes with a shell beside
// a fluid reach them, and inlined they made the loops of every scene slower (docs/performance.md, issue 18).
// Each adds its imaginary particles' terms to `sum` one by one, in the order of for_each_ghost.

// eq. (11) for the imaginary wall particles of shell particle j.
[[gnu::noinline]] void shell_density(const Particles& P, const FluidContext& ctx, std::size_t i, uint32_t j,
                                     const Vec3& xij, double& sum) {
  const ShellWall& sw = *ctx.shell_wall;
  sw.for_each_ghost(xij, i, j, P.body[j],
                    [&](const Vec3& r) { sum += sw.ghost_mass[j] * ctx.kernel.W(r.norm()); });
}

// Continuity, eq. (12), for the imaginary wall particles of shell particle j, which move with the shell.
[[gnu::noinline]] void shell_density_rate(const Particles& P, const FluidContext& ctx, std::size_t i,
                                          uint32_t j, const Vec3& xij, const Vec3& vi, double& drho) {
  const ShellWall& sw = *ctx.shell_wall;
  const CubicSpline& K = ctx.kernel;
  const double support2 = K.support * K.support;
  const Vec3 vij = vi - P.v[j];
  sw.for_each_ghost(xij, i, j, P.body[j], [&](const Vec3& rg) {
    const double rg2 = rg.squaredNorm();
    if (rg2 >= support2) return;
    const double rr = std::sqrt(rg2);
    drho += sw.ghost_mass[j] * (K.dWdr(rr) / rr) * vij.dot(rg);
  });
}

}  // namespace

void fluid_density_summation(Particles& P, const NeighborSearch& nb, const FluidContext& ctx) {
  const auto& idx = nb.index();
  const double w0 = ctx.kernel.W(0.0);
  parallel_for(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid || !ctx.params[P.material[i]].summation) return;
    // eq. (11): rho_i = sum_j m_j W_ij, self term included. Boundary particles carry the mass of the fluid
    // they stand in for, which keeps the sum complete next to walls.
    double rho = P.m[i] * w0;
    const ShellWall* sw = ctx.shell_wall;
    const uint32_t end = nb.end(i);
    for (uint32_t k = nb.begin(i); k < end; ++k) {
      const uint32_t j = idx[k];
      const Vec3 xij = ctx.separation(P.x[i], P.x[j]);
      if (sw && P.kind[j] == Kind::Shell) {  // the shell's imaginary wall particles
        shell_density(P, ctx, i, j, xij, rho);
        continue;
      }
      rho += P.m[j] * ctx.kernel.W(xij.norm());
    }
    P.rho[i] = rho;
  });
}

double summation_term(const Particles& P, const FluidContext& ctx, std::size_t i, uint32_t j,
                      const Vec3& xij) {
  if (ctx.shell_wall && P.kind[j] == Kind::Shell) {
    double sum = 0.0;
    shell_density(P, ctx, i, j, xij, sum);
    return sum;
  }
  return P.m[j] * ctx.kernel.W(xij.norm());
}

void fluid_pressure(Particles& P, const FluidContext& ctx) {
  parallel_for(P.size(), [&](std::size_t i) {
    if (P.kind[i] == Kind::Fluid) P.p[i] = ctx.params[P.material[i]].pressure(P.rho[i]);
  });
}

void fluid_pair_terms(const Particles& P, FluidContext& ctx) {
  ctx.p_over_rho2.resize(P.size());
  ctx.volume.resize(P.size());
  ctx.inv_rho.resize(P.size());
  parallel_for(P.size(), [&](std::size_t i) {
    ctx.p_over_rho2[i] = (P.p[i] - ctx.gauge) / (P.rho[i] * P.rho[i]);
    ctx.volume[i] = P.m[i] / P.rho[i];
    ctx.inv_rho[i] = 1.0 / P.rho[i];
  });
}

void fluid_density_rate(Particles& P, const NeighborSearch& nb, const FluidContext& ctx) {
  const auto& idx = nb.index();
  const CubicSpline& K = ctx.kernel;
  const double h = K.h;
  const double support2 = K.support * K.support;
  const bool shifts = ctx.shift_rate > 0.0 && P.shift.size() == P.size();
  // The loop over i's neighbours; with the shifts, each particle moves at v + shift_rate * shift (a
  // compile-time switch: the loop without them is the one the dam-break bench times).
  auto rate = [&](std::size_t i, auto with_shift) {
    const FluidParams& fi = ctx.params[P.material[i]];
    const Vec3 xi = P.x[i];
    Vec3 vi = P.v[i];
    if constexpr (decltype(with_shift)::value) vi += ctx.shift_rate * P.shift[i];
    const double rhoi = P.rho[i];
    const double diffusion = 2.0 * fi.delta * h * fi.c0;
    const double inv_c2 = 1.0 / (fi.c0 * fi.c0);
    double drho = 0.0;
    const ShellWall* sw = ctx.shell_wall;
    const uint32_t end = nb.end(i);
    for (uint32_t k = nb.begin(i); k < end; ++k) {
      const uint32_t j = idx[k];
      const Vec3 xij = ctx.separation(xi, P.x[j]);
      const double r2 = xij.squaredNorm();
      if (r2 >= support2 || r2 <= 0.0) continue;  // Verlet-list pairs in the skin: the kernel is zero there
      if (sw && P.kind[j] == Kind::Shell) {       // (a sheet does not shift)
        shell_density_rate(P, ctx, i, j, xij, vi, drho);
        continue;
      }
      const double r = std::sqrt(r2);
      const double dwdr_r = K.dWdr(r) / r;
      // Continuity, eq. (12) with x_ij = x_i - x_j, v_ij = v_i - v_j (the paper's minus sign belongs to
      // v_ji): approaching particles compress. A boundary particle contributes with its own velocity: this is
      // where a moving wall's velocity enters the fluid's density (Adami et al. 2012).
      Vec3 vj = P.v[j];
      if constexpr (decltype(with_shift)::value)
        vj += ctx.shift_rate * P.shift[j];  // zero for boundary particles
      drho += P.m[j] * dwdr_r * (vi - vj).dot(xij);
      // Density diffusion (Molteni & Colagrossi 2009, eq. 12) between particles of one fluid, minus the
      // hydrostatic density difference rho0 g.x_ji / c0^2 (Fourtakas et al. 2019, eq. 19, linearised Tait;
      // g without its periodic components, FluidContext::hydrostatic_gravity).
      if (diffusion > 0.0 && fluid_like(P.kind[j]) && P.material[j] == P.material[i]) {
        const double hydro = fi.rho0 * ctx.hydrostatic_gravity.dot(-xij) * inv_c2;  // x_j - x_i
        drho -= diffusion * (P.rho[j] - rhoi - hydro) * dwdr_r * ctx.volume[j];
      }
    }
    P.drho[i] = drho;
  };
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid) return;
    const FluidParams& fi = ctx.params[P.material[i]];
    if (fi.summation) return;
    if (shifts && fi.shifting_ale)
      rate(i, std::true_type{});
    else
      rate(i, std::false_type{});
  });
}

namespace {

// Acceleration of fluid particle i due to particle j (fluid or boundary): one term of the sums of eqs. (9)
// and (10) plus artificial viscosity. Zero beyond the kernel support. The same function gives the reaction on
// a moving boundary particle, so the force a body receives is exactly minus what the fluid feels. What the
// pair terms need of particle i, loaded once per particle rather than once per pair.
struct FluidI {
  std::size_t i;
  Vec3 x, v;
  double rho, p, p_over_rho2, inv_rho;
  const FluidParams* params;
  FluidI(const Particles& P, const FluidContext& ctx, std::size_t i)
      : i(i),
        x(P.x[i]),
        v(P.v[i]),
        rho(P.rho[i]),
        p(P.p[i]),
        p_over_rho2(ctx.p_over_rho2[i]),
        inv_rho(ctx.inv_rho[i]),
        params(&ctx.params[P.material[i]]) {}
};

struct PairConstants {
  double h, eta2, support2;
  explicit PairConstants(const CubicSpline& K)
      : h(K.h), eta2(0.01 * K.h * K.h), support2(K.support * K.support) {}  // 0.01 h^2 of eq. (10)
};

// Acceleration of fluid particle i due to one wall particle seen "locally" (fluid/shell_wall.hpp): at
// r = x_i - x_g, of mass mg, moving at v_w with acceleration a_w, with the pressure p_i + rho_i (g - a_w) .
// (x_g - x_i) extrapolated from i alone (cut at zero as for the other walls, boundary.cpp), its density from
// the equation of state, no slip through the mirrored velocity 2 v_w - v_i. background, when given,
// receives the background pressure's share (see fluid_reaction).
inline Vec3 local_wall_term(const FluidContext& ctx, const PairConstants& c, const FluidI& I,
                            const Vec3& r_ig, double mg, const Vec3& vij, const Vec3& g_minus_a,
                            Vec3* background) {
  const double r2 = r_ig.squaredNorm();
  if (r2 >= c.support2 || r2 <= 0.0) return Vec3::Zero();
  const FluidParams& fi = *I.params;
  const double r = std::sqrt(r2);
  const double dwdr = ctx.kernel.dWdr(r);
  const Vec3 gradW = (dwdr / r) * r_ig;
  // Pressures measured from the gauge (ctx.gauge, as in fluid_pair_terms); the density from the absolute one.
  const double pi = I.p - ctx.gauge;
  const double pg = std::max(pi + I.rho * g_minus_a.dot(-r_ig), 0.0);
  const double rhog = fi.density(pg + ctx.gauge);
  // The wall pushes and never pulls: i's own pressure enters cut at zero as well. With i in tension (p_i < 0:
  // behind an opening leaflet, in a vortex's core) the term -p_i / rho_i^2 drew i onto the imaginary wall and
  // through the sheet (docs/validation.md, stop 31). Unchanged wherever p_i >= 0.
  double scalar = -(std::max(pi, 0.0) / (I.rho * I.rho) + pg / (rhog * rhog));
  if (fi.alpha > 0.0) {
    const double vx = vij.dot(r_ig);
    if (vx < 0.0) scalar += fi.alpha * fi.c0 * (c.h * vx / (r2 + c.eta2)) / (0.5 * (I.rho + rhog));
  }
  Vec3 acc = (mg * scalar) * gradW;
  if (fi.nu > 0.0) acc += (fi.nu * mg * (1.0 / I.rho + 1.0 / rhog) * (r * dwdr) / (r2 + c.eta2) * 2.0) * vij;
  if (background && fi.p_background != 0.0)
    *background += (mg * fi.p_background * (1.0 / (I.rho * I.rho) + 1.0 / (rhog * rhog))) * gradW;
  return acc;
}

// Acceleration of fluid particle i due to the imaginary wall particles of shell particle j
// (fluid/shell_wall.hpp), each a local wall. Out of line, as the shell terms of the density loops.
[[gnu::noinline]] Vec3 shell_acceleration(const Particles& P, const FluidContext& ctx, const PairConstants& c,
                                          const FluidI& I, std::size_t j, const Vec3& xij, Vec3* background) {
  const ShellWall& sw = *ctx.shell_wall;
  const double mg = sw.ghost_mass[j];
  const Vec3 vij = I.v - P.v[j];
  const Vec3 g_minus_a = ctx.gravity - P.a[j];
  Vec3 acc = Vec3::Zero();
  sw.for_each_ghost(xij, I.i, j, P.body[j], [&](const Vec3& rg) {
    acc += local_wall_term(ctx, c, I, rg, mg, vij, g_minus_a, background);
  });
  return acc;
}

// The transport-velocity term of pair_acceleration (see there), out of line: only scenes with the
// formulation on reach it.
[[gnu::noinline]] Vec3 transport_stress(const Particles& P, const FluidContext& ctx, const FluidI& I,
                                        std::size_t j, const Vec3& gradW, double mj, double rhoj) {
  Vec3 stress = (ctx.transport_dv[I.i].dot(gradW) / I.rho) * I.v;
  if (P.kind[j] == Kind::Fluid) stress += (ctx.transport_dv[j].dot(gradW) / rhoj) * P.v[j];
  return mj * stress;
}

// The Riemann-solver dissipation's share of pair_acceleration's scalar (see there).
// Called for approaching pairs only (vx = v_ij . x_ij < 0): the others contribute nothing, and half the pairs
// of a flow separate, so the call is saved for them.
[[gnu::noinline]] double riemann_term(const FluidContext& ctx, const FluidParams& fi, const Particles& P,
                                      std::size_t j, double vx, double r, double rhoi, double rhoj) {
  const double du = -vx / r;  // U_L - U_R, positive: the caller passes approaching pairs only
  const double cbar = 0.5 * (fi.c0 + ctx.params[P.material[j]].c0);
  const double beta = std::min(fi.riemann_eta * du, cbar);
  return -2.0 * beta * du / (rhoi + rhoj);
}

// The tensile correction's share of pair_acceleration's scalar (see there).
[[gnu::noinline]] double tensile_term(const FluidContext& ctx, const FluidParams& fi, const FluidI& I,
                                      const Particles& P, std::size_t j, double r) {
  const double tension = std::max(-I.p_over_rho2, 0.0) + std::max(-ctx.p_over_rho2[j], 0.0);
  if (tension == 0.0) return 0.0;
  const double eps = 0.5 * (fi.tensile + ctx.params[P.material[j]].tensile);
  const double f = ctx.kernel.W(r) * ctx.inv_w_dx;
  const double f2 = f * f;
  return -eps * tension * f2 * f2;
}

// Particle shifting's sums of fluid particle i (fluid/shifting.hpp), carried by its force loop.
struct PairShift {
  ShiftSums& sums;
  double w_dx;  // W(dx)
};

// Inlined into the pair loops: out of line (GCC's choice once the shell and transport-velocity terms were
// added) the force loop of the aortic bench took about 15 % longer (docs/performance.md, issue 18).
// With `shift` (fluid_forces, where the material shifts), the pair's term of the shift's sums is added to
// shift->sums from the same r and grad W: one square root and one kernel gradient per pair instead of two,
// every sum bitwise what add_shift_neighbour gives (stop 43: the force phase of the physio scene 15 %
// shorter).
[[gnu::always_inline]] inline Vec3 pair_acceleration(const Particles& P, const FluidContext& ctx,
                                                     const PairConstants& c, const FluidI& I, std::size_t j,
                                                     Vec3* background = nullptr,
                                                     const PairShift* shift = nullptr) {
  const Vec3 xij = ctx.separation(I.x, P.x[j]);
  const double r2 = xij.squaredNorm();
  const bool shell_j = ctx.shell_wall && P.kind[j] == Kind::Shell;
  if (shift && shell_j) add_shift_ghosts(shift->sums, P, ctx, shift->w_dx, I.i, j, xij);
  if (r2 >= c.support2 || r2 <= 0.0) return Vec3::Zero();  // Verlet-list pairs in the skin
  // The imaginary particles lie farther from i than j itself, so the early return above holds for them.
  if (shell_j) return shell_acceleration(P, ctx, c, I, j, xij, background);
  const FluidParams& fi = *I.params;
  const double h = c.h, eta2 = c.eta2;
  const double r = std::sqrt(r2);
  const double dwdr = ctx.kernel.dWdr(r);
  const Vec3 gradW = (dwdr / r) * xij;  // grad_i W_ij
  const double mj = P.m[j];
  const double rhoi = I.rho;
  const double rhoj = P.rho[j];
  const bool fluid_j = fluid_like(P.kind[j]);  // open-boundary buffer particles count as fluid
  // ctx.volume[j] is m_j / rho_j of this very step (fluid_pair_terms runs just before the forces).
  if (shift) {
    shift->sums.add_gradient(xij, gradW, ctx.kernel.W(r) / shift->w_dx, ctx.volume[j],
                             fluid_j ? -1 : int32_t(P.body[j]));
    if (P.kind[j] == Kind::Inflow) shift->sums.beside_inflow = true;
  }
  const Vec3 vij = I.v - P.v[j];

  // Pressure, eq. (9) with the 1/rho_i of Algorithm 1 line 9 applied: a_i = -sum m_j (p_i/rho_i^2 +
  // p_j/rho_j^2) grad W. The factor is symmetric in i and j, so pair forces cancel exactly.
  double scalar = -(I.p_over_rho2 + ctx.p_over_rho2[j]);

  // Artificial viscosity (Monaghan 1992): only for approaching pairs.
  if (fi.alpha > 0.0) {
    const double vx = vij.dot(xij);
    if (vx < 0.0) {
      const double cbar = fluid_j ? 0.5 * (fi.c0 + ctx.params[P.material[j]].c0) : fi.c0;
      const double mu = h * vx / (r2 + eta2);
      scalar += fi.alpha * cbar * mu / (0.5 * (rhoi + rhoj));  // -Pi_ij, Pi_ij = -alpha c mu / rho
    }
  }
  // Riemann-solver dissipation (Zhang, Hu & Adams 2017, JCP 335:605, sec. 3): eq. (9) with the interface
  // pressure P* of a linearised Riemann problem along e_ij = (x_j - x_i)/r in place of the pair's pressures.
  // P*'s dissipative part rho_i rho_j beta (U_L - U_R) / (rho_i + rho_j), U_L - U_R = (v_i - v_j) . e_ij,
  // adds -2 beta (U_L - U_R) / (rho_i + rho_j) to the scalar below, with their low-dissipation limiter beta
  // = min(eta max(U_L - U_R, 0), c_bar): zero for separating pairs, quadratic in the approach speed of slow
  // ones (smooth flow keeps its energy), the acoustic impedance at an impact. Symmetric in i and j, so pair
  // forces still cancel. Fluid pairs only: with a wall particle's own velocity, flow along a wall
  // approaches the wall particles ahead and the term acts as a friction (the front of the Lobovsky dam break
  // arrived 17 % late; Zhang et al. use the wall-normal velocity, which these walls do not carry). The
  // solver's continuity half is left to delta-SPH. Out of line: only scenes with the key reach it.
  if (fi.riemann_eta > 0.0 && fluid_j) {
    const double vx = vij.dot(xij);
    if (vx < 0.0) scalar += riemann_term(ctx, fi, P, j, vx, r, rhoi, rhoj);
  }
  // Artificial pressure against the tensile instability (Monaghan 2000, J. Comput. Phys. 159:290, eqs. 4.2,
  // 4.3 and 4.7): the pair bracket p_i/rho_i^2 + p_j/rho_j^2 gains R f^n, f = W(r) / W(dx), n = 4, R = R_i +
  // R_j, R_i = eps |p_i| / rho_i^2 where p_i < 0 (zero otherwise): a short-range repulsion that appears only
  // under tension, where particles would otherwise pair up and clump. Symmetric in i and j (eps averaged
  // over the two materials), so pair forces still cancel. Fluid pairs only; out of line.
  if (fi.tensile > 0.0 && fluid_j) scalar += tensile_term(ctx, fi, I, P, j, r);
  Vec3 acc = (mj * scalar) * gradW;

  // Viscosity, eq. (10), in the form symmetric in i and j (Morris, Fox & Zhu 1997, eq. 8): 2/rho_j becomes
  // 1/rho_i + 1/rho_j, equal to eq. (10) at uniform density and exactly momentum conserving. Boundary
  // particles use their extrapolated no-slip velocity (Adami et al. 2012, eq. 22): a moving wall's velocity
  // enters the viscous force here. A free-slip body (Body::free_slip) is left out of the viscous sum: Adami
  // et al. impose no slip only through this term (the eq. 22 velocity enters nowhere else; the continuity
  // equation uses the wall's own velocity), so without it no shear stress reaches the fluid from the body's
  // surface. Its pressure term is unchanged, so the body still holds the fluid out; artificial viscosity, a
  // shock-capturing dissipation of approaching pairs, is unchanged too.
  const double nu = fluid_j ? 0.5 * (fi.nu + ctx.params[P.material[j]].nu) : fi.nu;
  if (nu > 0.0 && (fluid_j || !ctx.free_slip_of(P.body[j]))) {
    const Vec3 vij_visc = fluid_j ? vij : Vec3(I.v - P.v_wall[j]);
    const double f = nu * mj * (I.inv_rho + ctx.inv_rho[j]) * (r * dwdr) / (r2 + eta2);  // 1/rho_i + 1/rho_j
    acc += f * vij_visc;
  }

  // Transport-velocity formulation (fluid/transport_velocity.hpp; Adami, Hu & Adams 2013, sec. 2): the
  // momentum equation along the transport velocity carries the extra stress A = rho v (v~ - v), (1/rho) div
  // A, here in the symmetric form of the pressure term, m_j (A_i / rho_i^2 + A_j / rho_j^2) . grad W, with A
  // . grad W = rho v ((v~ - v) . grad W). A is zero for boundary particles (they move with their own
  // velocity) and for fluid without the formulation (its v~ - v is zero).
  if (!ctx.transport_dv.empty()) acc += transport_stress(P, ctx, I, j, gradW, mj, rhoj);
  return acc;
}

}  // namespace

void fluid_forces(Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                  const ShiftRequest* shift) {
  const auto& idx = nb.index();
  const PairConstants c(ctx.kernel);
  const double w_dx = shift ? ctx.kernel.W(shift->dx) : 0.0;
  if (shift) shift->out->assign(P.size(), Vec3::Zero());
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Fluid) return;
    const FluidI I(P, ctx, i);
    const double A = shift ? I.params->shifting : 0.0;
    Vec3 acc = Vec3::Zero();
    ShiftSums sums;
    const PairShift pair_shift{sums, w_dx};
    // Particle shifting's sums over the same neighbours, in the same order (fluid/shifting.hpp).
    auto add_shift = [&](uint32_t j) {
      add_shift_neighbour(sums, P, ctx, w_dx, i, j, ctx.separation(I.x, P.x[j]));
    };
    const uint32_t end = nb.end(i);
    const uint32_t local = ctx.shell_wall ? std::min(end, ctx.shell_wall->local_begin[i]) : end;
    // Two copies of the loop on purpose: with the shift's branch inside one loop the force phase of the
    // dam-break bench (no shifting) took 10-25 % longer (stop 31, alternated `bench --quick --threads 1`).
    if (A > 0.0) {
      for (uint32_t k = nb.begin(i); k < local; ++k)
        acc += pair_acceleration(P, ctx, c, I, idx[k], nullptr, &pair_shift);
    } else {
      for (uint32_t k = nb.begin(i); k < local; ++k) acc += pair_acceleration(P, ctx, c, I, idx[k]);
    }
    for (uint32_t k = local; k < end; ++k) {  // walls across a sheet (fluid/shell_wall.hpp)
      const uint32_t j = idx[k];
      acc += local_wall_term(ctx, c, I, ctx.separation(I.x, P.x[j]), P.m[j], I.v - P.v[j],
                             ctx.gravity - P.a[j], nullptr);
      if (A > 0.0) add_shift(j);
    }
    P.a[i] = acc + ctx.gravity;
    if (A > 0.0) (*shift->out)[i] = shift_at(sums, *I.params, ctx.kernel.h, I.v.norm(), shift->dt, shift->dx);
  });
}

void fluid_reaction(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                    std::vector<Vec3>& f) {
  const auto& idx = nb.index();
  const PairConstants c(ctx.kernel);
  parallel_for_dynamic(P.size(), [&](std::size_t j) {
    if (fluid_like(P.kind[j]) || P.kind[j] == Kind::Wall) return;
    Vec3 sum = Vec3::Zero();
    for (uint32_t k = nb.begin(j); k < nb.end(j); ++k) {
      const uint32_t i = idx[k];
      if (P.kind[i] != Kind::Fluid) continue;
      const FluidI I(P, ctx, i);
      if (ctx.shell_wall && P.kind[j] == Kind::Shell) {  // the same background rule, per imaginary particle
        Vec3 background = Vec3::Zero();
        const Vec3 a = pair_acceleration(P, ctx, c, I, j, &background);
        sum -= P.m[i] * (a + background);
        continue;
      }
      Vec3 a = pair_acceleration(P, ctx, c, I, j);
      // The background pressure is a device of the fluid's discretisation (it keeps the fluid's pressure
      // positive against the tensile instability), not a load on the body: a uniform pressure has no net
      // force on a closed body, but its discrete sum would squeeze a soft solid (a 2 kPa background on a
      // 5 kPa leaflet). Its share of the pair term, -m_j pb (1/rho_i^2 + 1/rho_j^2) grad W (the boundary
      // particle's extrapolated pressure carries the same pb), is left out of the reaction.
      const double pb = I.params->p_background;
      if (pb != 0.0) {
        const Vec3 xij = I.x - P.x[j];
        const double r = xij.norm();
        if (r > 0.0 && r < ctx.kernel.support)
          a += P.m[j] * pb * (1.0 / (I.rho * I.rho) + 1.0 / (P.rho[j] * P.rho[j])) *
               (ctx.kernel.dWdr(r) / r) * xij;
      }
      sum -= P.m[i] * a;
    }
    f[j] += sum;
  });
}

}  // namespace aortasph
