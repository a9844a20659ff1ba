// Weakly compressible SPH fluid, paper section 3.1 and Algorithm 1:
//   density by the continuity equation (eq. 12) or by summation (eq. 11), Tait equation of state (eq. 13),
//   pressure gradient in the symmetric form (eq. 9), Laplacian viscosity (eq. 10), gravity.
// Stabilisers, each switchable per material in the scene:
//   - density diffusion ("delta-SPH"): Molteni & Colagrossi 2009, Comput. Phys. Commun. 180:861, with the
//     hydrostatic correction of Fourtakas et al. 2019, Comput. Fluids 190:346 (so a fluid at rest stays at
//     rest);
//   - artificial viscosity: Monaghan 1992, Annu. Rev. Astron. Astrophys. 30:543, eq. (4.2).
// Boundary particles (walls, later rigid and elastic bodies) enter the sums through the values the wall
// boundary (boundary.hpp) gives them: pressure, density and a no-slip velocity.
#pragma once

#include <cmath>

#include "core/kernel.hpp"
#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "core/periodic.hpp"
#include "fluid/shell_wall.hpp"

namespace aortasph {

// Per-material constants derived once from the scene (read-only during a run).
struct FluidParams {
  double rho0 = 1000.0;
  double c0 = 20.0;
  double gamma = 7.0;
  double B = 0.0;  // Tait stiffness k = rho0 c0^2 / gamma, eq. (13)
  double nu = 0.0;
  double delta = 0.0;
  double alpha = 0.0;
  double riemann_eta = 0.0;  // Riemann-solver dissipation limiter (Zhang, Hu & Adams 2017); 0: off
  double tensile = 0.0;      // Monaghan 2000's artificial-pressure epsilon; 0: off
  double p_background = 0.0;
  double shifting = 0.0;      // particle shifting coefficient A (fluid/shifting.hpp)
  bool shifting_ale = false;  // the shift enters the density (fluid/shifting.hpp)
  bool mask_density = false;  // the masks' changes enter the density (boundary/mask_density.hpp)
  double tv_pb = 0.0;         // transport-velocity background pressure p_b (fluid/transport_velocity.hpp)
  bool summation = false;

  explicit FluidParams(const Material& m)
      : rho0(m.density),
        c0(m.sound_speed),
        gamma(m.eos_exponent),
        B(m.density * m.sound_speed * m.sound_speed / m.eos_exponent),
        nu(m.viscosity),
        delta(m.delta_sph),
        alpha(m.artificial_viscosity),
        riemann_eta(m.riemann_dissipation),
        tensile(m.tensile_correction),
        p_background(m.background_pressure),
        shifting(m.shifting),
        shifting_ale(m.shifting > 0.0 && m.shifting_ale && !m.density_summation),
        mask_density(m.mask_density && !m.density_summation),
        tv_pb(m.transport_velocity_pb),
        summation(m.density_summation) {}
  FluidParams() = default;

  // Tait equation, eq. (13): p = k ((rho / rho0)^gamma - 1).
  double pressure(double rho) const { return B * (std::pow(rho / rho0, gamma) - 1.0) + p_background; }
  // Its inverse, for boundary particles that receive a pressure.
  double density(double p) const {
    return rho0 * std::pow(std::max((p - p_background) / B + 1.0, 1e-6), 1.0 / gamma);
  }
};

struct FluidContext {
  const CubicSpline& kernel;
  const std::vector<FluidParams>& params;  // indexed by material; only fluid entries are valid
  Vec3 gravity;
  // Per-particle factors of the pair sums, computed once per step instead of once per pair.
  std::vector<double> p_over_rho2;  // p / rho^2
  std::vector<double> volume;       // m / rho
  Periodic periodic;                // periodic axes: pair separations are nearest images
  // The part of gravity a fluid at rest balances with its pressure: gravity less its components along
  // periodic axes (Periodic::across); the hydrostatic density difference of the density diffusion uses it.
  Vec3 hydrostatic_gravity = Vec3::Zero();
  // Shells seen as two-sided walls (fluid/shell_wall.hpp); null when the scene has no shell beside a fluid.
  const ShellWall* shell_wall = nullptr;
  // 1 / dt of this step when the continuity equation (fluid_density_rate) takes in the particles' shifts of
  // the last step (Particles::shift, spread over this step as a velocity) for materials with shifting_ale:
  // the shift counted in the density (fluid/shifting.hpp). 0: not counted.
  double shift_rate = 0.0;
  // Per body: 1 for a free-slip boundary body (Body::free_slip), whose particles take no part in the
  // viscous term; empty when every body is no-slip.
  std::vector<uint8_t> free_slip = {};
  bool free_slip_of(uint32_t body) const { return !free_slip.empty() && free_slip[body]; }
  // Per particle: the transport velocity's correction v~ - v of this step (fluid/transport_velocity.hpp),
  // zero where a material has it off; empty when no material has it on.
  std::vector<Vec3> transport_dv = {};
  double inv_w_dx = 0.0;  // 1 / W(particle spacing): the tensile correction's reference (World sets it)
  // The pressure gauge p_g [Pa] (docs/model.md, "Pressure gauge"): the pair terms of the momentum equation
  // use p - p_g, one value for every particle, so pair forces still cancel and a uniform pressure still has
  // no effect, but the zeroth-order error of the SPH gradient, proportional to the pressure itself, is not
  // multiplied by a pressure level that the flow does not feel. World sets it each step (0: off).
  double gauge = 0.0;
  // Per particle: 1 / rho, for the viscous term (one division per particle and step, not one per pair).
  std::vector<double> inv_rho = {};
  // x_i - x_j, or its nearest image along periodic axes.
  Vec3 separation(const Vec3& xi, const Vec3& xj) const {
    return periodic.any ? periodic.image(xi - xj) : Vec3(xi - xj);
  }
};

// Fills ctx.p_over_rho2 ((p - ctx.gauge) / rho^2), ctx.volume and ctx.inv_rho from the current p and rho.
void fluid_pair_terms(const Particles& P, FluidContext& ctx);

// Density by summation, eq. (11), for fluid particles whose material asks for it.
void fluid_density_summation(Particles& P, const NeighborSearch& nb, const FluidContext& ctx);
// Neighbour j's term of eq. (11) for fluid particle i, x_ij = x_i - x_j: m_j W_ij, or for a shell particle
// its imaginary wall particles' sum_g m_g W_ig on i's side of the sheet (fluid/shell_wall.hpp).
double summation_term(const Particles& P, const FluidContext& ctx, std::size_t i, uint32_t j,
                      const Vec3& xij);

// Pressure from density, eq. (13), for every fluid particle.
void fluid_pressure(Particles& P, const FluidContext& ctx);

// d rho / dt of every fluid particle by continuity (eq. 12) plus density diffusion.
void fluid_density_rate(Particles& P, const NeighborSearch& nb, const FluidContext& ctx);

// Acceleration of every fluid particle: pressure (eq. 9), viscosity (eq. 10), artificial viscosity, gravity.
// Gathers: each fluid particle writes only its own a.
// With `shift` (World::step, where a material shifts): the particle shifting of fluid/shifting.hpp for a
// step of dt at spacing dx, its sums carried by the same neighbour loop (bitwise the stand-alone
// fluid_shifting's at the same positions), written to (*shift)[i].
struct ShiftRequest {
  double dx = 0.0, dt = 0.0;
  std::vector<Vec3>* out = nullptr;
};
void fluid_forces(Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                  const ShiftRequest* shift = nullptr);

// Adds to f[j], for every moving boundary particle j (rigid, elastic), the force the fluid exerts on it:
// minus the sum of m_i a_ij over its fluid neighbours i, with the very pair terms of fluid_forces (Newton's
// third law; Adami et al. 2012 section 2.4).
void fluid_reaction(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                    std::vector<Vec3>& f);

}  // namespace aortasph
