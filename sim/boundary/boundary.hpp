// Generalised wall boundary condition of Adami, Hu & Adams 2012, J. Comput. Phys. 231:7057.
// Every non-fluid particle (fixed wall, and later rigid and elastic bodies) is a boundary particle. Each step
// it takes from the fluid around it
//   - a pressure, eq. (27):  p_w = (sum_f p_f W_wf + (g - a_w) . sum_f rho_f x_wf W_wf) / sum_f W_wf,
//   - a density from that pressure through the fluid's equation of state (eq. 28),
//   - a velocity for the viscous (no-slip) term, eq. (22): v~_w = 2 v_w - sum_f v_f W_wf / sum_f W_wf.
// The wall's own velocity v_w and acceleration a_w are the particle's v and a: for a fixed wall both are
// zero, for a moving body they are the body's, so moving bodies couple to the fluid through this same code.
#pragma once

#include "fluid/fluid_wcsph.hpp"

namespace aortasph {

// ref: the fluid parameters used to turn a boundary pressure into a density (the scene's first fluid).
void boundary_from_fluid(Particles& P, const NeighborSearch& nb, const FluidContext& ctx,
                         const FluidParams& ref);

}  // namespace aortasph
