// How the fluid sees a one-layer shell: as a wall on whichever side the fluid particle is (issue 16 item 3;
// docs/model.md, "Fluid on both sides of a shell").
//
// A shell particle j (mid-surface point x_j, unit director n_j, reference area A_j) stands, for a fluid
// particle i, for a stack of imaginary wall particles on the side away from i: at
//     x_g,k = x_j - sigma (k - 1/2) dx n_j,   k = 1 .. K,   sigma = sign(n_j . (x_i - x_j)),
// each of volume A_j dx (a wall slab of thickness dx behind the mid-surface, K dx covering the kernel
// support), so that i's kernel support is as full as next to a plain wall of layered particles. This is
// the ghost stacking of SPHinXsys's fluid-shell coupling (Wu, Zhang & Hu; /work/shared/reference/shell.md
// sections 2.1-2.2), with the ghost side chosen per pair instead of per body, which is what lets fluid sit on
// BOTH sides. The imaginary particles carry a pressure extrapolated from i alone (side-local by
// construction),
//     p_g = p_i + rho_i (g - a_j) . (x_g - x_i)
// (the hydrostatic and moving-wall terms of Adami, Hu & Adams 2012, eq. 27, applied to one fluid particle,
// as SPHinXsys's wall pressure for shells), cut at zero like the other walls, a density from the equation of
// state, the shell's velocity v_j in the continuity equation and the mirrored velocity 2 v_j - v_i in the
// viscous term (no slip). Fluid-fluid pairs across a sheet are masked out of the neighbour lists
// (sim/boundary/ shell_coupling.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/particles.hpp"

namespace aortasph {

struct ShellWall {
  // By particle index, filled each step for shell particles (others unused).
  std::vector<Vec3> normal;        // the director n_j
  std::vector<double> ghost_mass;  // rho_ref A_j dx per imaginary particle
  // By particle: where the "local walls" of its neighbour row begin (sim/boundary/shell_coupling.hpp):
  // wall particles across a sheet, seen with a pressure extrapolated from this fluid particle alone, like
  // the imaginary particles. kNoLocal: none.
  static constexpr uint32_t kNoLocal = 0xffffffffu;
  std::vector<uint32_t> local_begin;
  double dx = 0.0;  // layer spacing
  int layers = 0;   // K

  // Calls f(r_ig) with r_ig = x_i - x_g for each imaginary particle of shell particle j seen from i, where
  // xij = x_i - x_j.
  template <class F>
  void for_each_ghost(const Vec3& xij, std::size_t j, F&& f) const {
    const Vec3& n = normal[j];
    const double sigma = n.dot(xij) >= 0.0 ? 1.0 : -1.0;
    for (int k = 1; k <= layers; ++k) f(Vec3(xij + (sigma * (k - 0.5) * dx) * n));
  }
};

}  // namespace aortasph
