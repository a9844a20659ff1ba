// Transport-velocity formulation for the fluid (issue 20): Adami, Hu & Adams 2013, "A transport-velocity
// formulation for smoothed particle hydrodynamics", J. Comput. Phys. 241:292-307.
// (The paper's text was not at hand. Its equation numbers, as PySPH's implementation cites them: eq. (13)
// the background-pressure acceleration a_b below, eqs. (14)-(16) the velocity-Verlet steps with
// v~(t + dt/2) = v(t + dt/2) + (dt/2) a_b, eq. (8) the momentum equation with A, eq. (7) the
// inter-particle-averaged pressure that the force here replaces by the symmetric form of eq. (9) of the
// project's paper; an independent 2-D implementation with eq. (7) and the paper's quintic kernel gives the
// same Taylor-Green energy history, docs/validation.md.) On an exact lattice the sum below is zero on any
// uniformly strained patch (mirror symmetry), so a_b cannot keep a strained lattice isotropic: start such
// flows from a jittered lattice (Body::jitter).
//
// Particles are advected with a transport velocity v~ that differs from their momentum velocity v by the
// acceleration of a constant background pressure p_b, which pushes them from where they crowd to where they
// thin out (a uniform p_b has no effect on the continuum, but its discrete gradient does not vanish on a
// disordered particle set):
//
//   dr_i/dt = v~_i,   v~_i(t + dt/2) = v_i(t + dt/2) + (dt/2) a_b,i(t),
//   a_b,i = -(p_b / m_i) sum_j (V_i^2 + V_j^2) dW_ij/dr_ij e_ij         (V = m / rho, e_ij = x_ij / r_ij;
//                                                                        Adami et al. sec. 3, the discrete
//                                                                        -grad p_b / rho of their
//                                                                        inter-particle-averaged pressure
//                                                                        gradient, and sec. 3.4's
//                                                                        velocity-Verlet half step),
//
// while the momentum equation, taken along v~, gains the divergence of A = rho v (v~ - v) (sec. 2; the pair
// term is in fluid_wcsph.cpp). Momentum is conserved: a_b moves particles and never enters v; the A term is
// antisymmetric in each fluid pair. The sum runs over fluid and boundary neighbours (walls, rigid and elastic
// particles, with the volumes the wall boundary gives them), so that particles next to a wall are not pulled
// into it, as in Adami et al.
//
// Confined flows only. At a free surface the neighbours on one side are missing, a_b points out of the fluid
// and would spray the surface particles off. This implementation turns the correction off (v~ = v) for a
// particle whose kernel divergence of position, div r_i = -sum_j V_j grad_i W_ij . x_ij (3 in the bulk), is
// under 2.5 (the free-surface test of fluid/shifting.hpp), and for a particle next to a shell (the shells'
// imaginary wall particles are not in the sum). The material must use density summation (eq. 11), as Adami
// et al. do: the density then follows the particles wherever v~ takes them (the continuity equation would
// follow v, not v~).
#pragma once

#include <vector>

#include "fluid/fluid_wcsph.hpp"

namespace aortasph {

// v~ - v = (dt/2) a_b of every fluid particle whose material has tv_pb > 0 (zero for the others), from the
// positions, masses and densities now (ctx.volume must be current). Gathers: each particle writes only its
// own entry.
void fluid_transport_velocity(const Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                              double dt, std::vector<Vec3>& dv);

}  // namespace aortasph
