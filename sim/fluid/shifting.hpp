// Particle shifting for the fluid (issue 20): a small displacement per step that moves fluid particles down
// the gradient of their own concentration, so that they stay evenly spaced where plain WCSPH lets them string
// out and clump (stagnation points, expanding flows: the tensile instability). Fickian form of Lind, Xu,
// Stansby & Rogers 2012 (J. Comput. Phys. 231:1499-1523, eqs. 13-18) with the diffusion coefficient of
// Skillen, Lind, Stansby & Rogers 2013 (Comput. Methods Appl. Mech. Engrg. 265:163-173):
//
//   dr_i = -D_i grad C_i,   D_i = A h |v_i| dt,
//   grad C_i = sum_j V_j [1 + R (W_ij / W(dx))^n] grad_i W_ij   (R = 0.2, n = 4: Monaghan 2000's
//              anti-clumping term, which Lind et al. add so that pairs closer than dx repel more),
//
// over all neighbours (fluid, buffers and boundary particles, which complete the concentration field next to
// walls). A is the material's `shifting` coefficient (0: off; Skillen et al. use 1..6, 2 is the common
// choice). Near a free surface the concentration drops for want of neighbours, not for disorder: where the
// particle's kernel divergence of position, div r_i = -sum_j V_j grad_i W_ij . x_ij (3 in the bulk in 3-D),
// is under 2.5, only the part of dr tangent to the surface (normal -grad C / |grad C|) is kept, and under 1.5
// (a splash) none (Lind et al. 2012 sec. 3.3 treat the surface the same way, with 2-D thresholds). Next to a
// boundary (a wall, rigid or elastic particle in the support; not a shell, whose two-sided coupling keeps the
// fluid off it, fluid/shell_wall.hpp: with shells in this rule, single particles went 0.8 dx into the root's
// wall at the leaflet nadirs by 0.03 s of the physio scene, stop 42) the shift never moves a particle towards
// it: each boundary body's direction is that of its particles' share of sum_j V_j grad W, and dr loses its
// part along those it points towards (beside two, a floor meeting a side wall, it keeps at most the part
// along the corner's line), while a part away from a body is kept (the anti-clumping term of grad C pushes a
// particle that came too close off the wall). The concentration next to a boundary is not the bulk's (a
// curved wall's rings are not on the fluid's lattice), so the part towards it pushed the near-wall particles
// steadily into the wall, the pressure pushed them back, and the velocity that did so was a real one to the
// continuity and momentum equations: in a tube between two equal imposed pressures the flow accelerated by
// itself, 456 -> 835 ml/s in 80 ms (the outflow buffer's push on the fluid 6 % low), where without shifting
// it stays at 455 -> 430 (docs/validation.md, "Shifting beside walls", stop 42). A shift is capped at 0.1 dx
// per step. A particle beside a sheet (a shell's imaginary particles in its support) does not shift at all
// (shift_at); the sheet's own coupling orders the fluid next to it. Stop 44 made that rule for shifting_ale
// (see the end of this file): single particles in the pocket at the valve's centre, where three leaflets
// meet and the blood ran at 5-10 m/s, shifted by the cap at every step, faster than they moved, and drained
// to 0.84 rho0 at -130 kPa within 10 ms of the physio scene. Stop 50 made it for every material: without the
// shift counted in the density, those shifts moved particles apart without their density falling, so the
// blood that passed the leaflets filled 6-12 % more volume than its density said (Voronoi volumes of the
// physio run's particles), the aorta lost 15 % of its particles in ejection while its density held, and the
// continuity density (eq. 12) never saw it; a flap in a tube shows the same (test [shell_fluid] "blood
// flowing past a flap"). The velocity is not Taylor-corrected for the shift (as in the Fickian WCSPH schemes
// of Skillen et al.); the density is only where a material asks for it (shifting_ale, off by default: with
// it, blood lined up in a commissure post's plane went through the wall above the post from 50 ms, drained
// there and the physio scene stopped at 79 ms, stops 44-45, scripts/wall_leak.py); mass and momentum are
// untouched, so they stay conserved exactly.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "fluid/fluid_wcsph.hpp"

namespace aortasph {

// The per-particle sums of the shift, grad C_i and div r_i, one neighbour at a time (so that the force loop
// can carry them: fluid_forces), and the shift they give.
struct ShiftSums {
  Vec3 grad_c = Vec3::Zero();
  double div_r = 0.0;
  // Each boundary body's share of sum_j V_j grad_i W_ij, body by body (shift_from's wall rule): it points
  // from the particle towards that body. Up to kBodies bodies; the shares of any further ones are added to
  // the last.
  static constexpr int kBodies = 4;
  std::array<Vec3, kBodies> boundary;
  std::array<int32_t, kBodies> boundary_body;
  int boundaries = 0;
  bool near_sheet = false;     // a sheet's imaginary particles are in the support (shift_at)
  bool beside_inflow = false;  // an inflow buffer particle is in the support (shift_at, with shifting_ale)
  // Neighbour j at x_ij = x_i - x_j (|x_ij|^2 = r2, inside the support), volume V_j = m_j / rho_j;
  // w_dx = W(dx); body: j's body when j is a wall, rigid or elastic particle, -1 for fluid and shells.
  void add(const CubicSpline& K, double w_dx, const Vec3& xij, double r2, double vj, int32_t body) {
    const double r = std::sqrt(r2);
    add_gradient(xij, (K.dWdr(r) / r) * xij, K.W(r) / w_dx, vj, body);
  }
  // The same with grad_i W_ij and q = W_ij / W(dx) already known (the force loop computes grad W for its
  // own terms: fluid_forces).
  void add_gradient(const Vec3& xij, const Vec3& grad_w, double q, double vj, int32_t body) {
    constexpr double R = 0.2;
    grad_c += (vj * (1.0 + R * q * q * q * q)) * grad_w;
    div_r -= vj * grad_w.dot(xij);
    if (body >= 0) add_boundary(body, vj * grad_w);
  }
  void add_boundary(int32_t body, const Vec3& g) {
    for (int k = 0; k < boundaries; ++k)
      if (boundary_body[k] == body) {
        boundary[k] += g;
        return;
      }
    if (boundaries < kBodies) {
      boundary_body[boundaries] = body;
      boundary[boundaries++] = g;
    } else {
      boundary[kBodies - 1] += g;
    }
  }
};
// The shell branch of add_shift_neighbour, out of line: only scenes with a shell beside a fluid reach it.
[[gnu::noinline]] void add_shift_ghosts(ShiftSums& s, const Particles& P, const FluidContext& ctx,
                                        double w_dx, std::size_t i, uint32_t j, const Vec3& xij);
// Adds neighbour j of fluid particle i (x_ij = x_i - x_j) to i's sums, if inside the support. A shell
// particle stands for its imaginary wall particles (fluid/shell_wall.hpp), each of volume A_j dx, on the far
// side of the sheet from i: the concentration next to a sheet is then that next to a plain wall. (With the
// shell particle itself in the sums, at its own position and volume, the rows beside a sheet saw a
// concentration gradient across it, 2.26 1/m against 4e-4 beside a wall: test [shell_fluid].)
inline void add_shift_neighbour(ShiftSums& s, const Particles& P, const FluidContext& ctx, double w_dx,
                                std::size_t i, uint32_t j, const Vec3& xij) {
  if (ctx.shell_wall && P.kind[j] == Kind::Shell) return add_shift_ghosts(s, P, ctx, w_dx, i, j, xij);
  const double r2 = xij.squaredNorm();
  const double support2 = ctx.kernel.support * ctx.kernel.support;
  if (r2 < support2 && r2 > 0.0) {
    s.add(ctx.kernel, w_dx, xij, r2, P.m[j] / P.rho[j],
          fluid_like(P.kind[j]) || P.kind[j] == Kind::Shell ? -1 : int32_t(P.body[j]));
    if (P.kind[j] == Kind::Inflow) s.beside_inflow = true;
  }
}

// The shift of a particle with coefficient A, speed |v|, for a step of dt (the surface rule and the cap).
Vec3 shift_from(const ShiftSums& s, double A, double h, double speed, double dt, double dx);
// The same for a particle of material f: none beside a sheet (its imaginary particles in the support; see the
// header comment), and with `shifting_ale` none beside an inflow buffer. The buffer's particles do not shift
// and sit on the inlet's lattice, by the wall closer than the fluid's own spacing (0.8-0.9 dx from its first
// layer in the physio scene); with the shift counted in the density, blood that had just left the pressure
// inlet's buffer moved outwards into the LVOT wall within 10 ms (the diastole testbed: 5-7 particles in the
// wall at 90-100 ms; with this rule 0-1, and 0 at 90-100 ms; docs/validation.md, "Stop 55").
inline Vec3 shift_at(const ShiftSums& s, const FluidParams& f, double h, double speed, double dt, double dx) {
  if (s.near_sheet || (f.shifting_ale && s.beside_inflow)) return Vec3::Zero();
  return shift_from(s, f.shifting, h, speed, dt, dx);
}

// Shift of every fluid particle whose material has shifting > 0 (zero for the others), from the positions
// and velocities now, for a step of dt. Gathers: each particle writes only its own entry. (World::step has
// fluid_forces carry the same sums in its neighbour loop instead: one pass fewer; this stand-alone pass is
// the reference the test compares it with.)
void fluid_shifting(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx, double dx,
                    double dt, std::vector<Vec3>& shift);

// The shift counted in the density (a material's shifting_ale): the density of each such particle takes in
// the change the shift makes, the continuity equation (eq. 12) with the shift's displacement in place of
// v dt,
//
//   delta rho_i = sum_j m_j (dr_i - dr_j) . grad_i W_ij,
//
// over the same neighbours as eq. (12) (boundary particles and buffers that did not shift: dr_j = 0; a
// sheet's imaginary particles stand for its particles, fluid/shell_wall.hpp). This is the first-order change
// of the summation density rho_i = sum_j m_j W_ij under the shift (test: [periodic] "the shift's density
// change"), and the divergence term of the ALE form of the continuity equation in the consistent shifting of
// Sun, Colagrossi, Marrone, Antuono & Zhang 2019 (Comput. Methods Appl. Mech. Engrg. 348:912-934, recalled;
// the term delta u . grad rho is left out, as in the shifting itself). World::step keeps each particle's
// shift (Particles::shift) and the next step's continuity equation takes it in, spread over that step as a
// velocity, v + dr / dt (fluid_density_rate, FluidContext::shift_rate): no neighbour pass of its own (as one
// it cost 16 % of the physio scene's step). Without the change the shift rearranges the particles while their
// densities stay what the flow made them: shifting packed the physio scene's aorta, 4 % more particles per
// volume than the density said by 150 ms, and the open boundaries let the surplus in (docs/validation.md,
// stops 43 and 44). Mass is untouched; the density's total changes only where particles shift towards or
// away from boundary particles.

}  // namespace aortasph
