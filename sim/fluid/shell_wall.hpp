// How the fluid sees a one-layer shell: as a wall on whichever side the fluid particle is (issue 16 item 3;
// docs/model.md, "Fluid on both sides of a shell").
//
// A shell particle j (mid-surface point x_j, unit director n_j, reference area A_j) stands, for a fluid
// particle i, for a stack of imaginary wall particles on the side away from i: at
//     x_g,k = x_j - sigma (k - 1/2) dx n_j,   k = 1 .. K,   sigma = i's side of the sheet (sigma() below),
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

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "core/particles.hpp"

namespace aortasph {

struct ShellWall {
  // By particle index, filled each step for shell particles (others unused).
  std::vector<Vec3> normal;        // the director n_j
  std::vector<double> ghost_mass;  // rho_ref A_j dx per imaginary particle
  // By particle: for a particle on the rim of a free edge (the outermost row of an edge the fluid can pass
  // round: sim/boundary/shell_coupling.cpp), its current outward in-plane direction e_j; zero elsewhere
  // (see for_each_ghost).
  std::vector<Vec3> cap;
  // By particle: where the "local walls" of its neighbour row begin (sim/boundary/shell_coupling.hpp):
  // wall particles across a sheet, seen with a pressure extrapolated from this fluid particle alone, like
  // the imaginary particles. kNoLocal: none.
  static constexpr uint32_t kNoLocal = 0xffffffffu;
  std::vector<uint32_t> local_begin;
  // By particle: the fluid particle's side of each shell body near it, from its side label this step
  // (sim/boundary/shell_coupling.hpp; the sign of n_s . (x_i - x_s) for the body's nearest particle s).
  static constexpr int kSides = 4;
  struct Sides {
    std::array<uint16_t, kSides> body{};
    std::array<int8_t, kSides> side{};
    uint8_t n = 0;
  };
  std::vector<Sides> sides;
  double dx = 0.0;         // layer spacing
  int layers = 0;          // K
  double ghost_rho = 0.0;  // the imaginary particles' density: ghost_mass / ghost_rho is their volume A_j dx

  // The side sigma on which fluid particle i sees the sheet of body `body_j` near shell particle j: its
  // label for that body when it has one, otherwise the side of j's own tangent plane. The label, not the
  // pair's geometry, decides: with the geometric sign a fluid particle that drifts into the plane of a
  // particle near a free edge (n_j . x_ij ~ 0) is pushed on by the imaginary particles to whichever side it
  // happens to be on, an unstable balance that let fluid slip through the last half spacing of a sheet;
  // with the label it is pushed back to its own side, and all of a sheet's particles present their wall on
  // the same side of a fluid particle, also where the sheet curves.
  double sigma(const Vec3& xij, std::size_t i, std::size_t j, uint16_t body_j) const {
    if (i < sides.size()) {
      const Sides& S = sides[i];
      for (uint8_t q = 0; q < S.n; ++q)
        if (S.body[q] == body_j) return S.side[q];
    }
    return normal[j].dot(xij) >= 0.0 ? 1.0 : -1.0;
  }

  // Calls f(r_ig) with r_ig = x_i - x_g for each imaginary particle of shell particle j (of body body_j)
  // seen from fluid particle i, where xij = x_i - x_j.
  //
  // On the rim of a free edge (cap[j] = e_j, the outward in-plane direction) the stack slides with i along
  // e_j over the half spacing that j's area A_j reaches beyond it: for a = e_j . x_ij > 0 it stands at
  // x_j + min(a, dx / 2) e_j instead of x_j. A fluid particle over that strip then has a stack right under
  // it, as over the inside of the sheet, and one beyond the strip sees the stack at the sheet's edge. With
  // the stack at x_j only, a particle swinging round the edge over the strip saw its nearest imaginary
  // particle 0.6-0.8 dx away and was not stopped: in the aortic shell scene such particles reached the
  // sheet's plane at 0.3-0.5 m/s across it and were put back by the guard (docs/validation.md, stop 26).
  // Continuous in x_i; the total imaginary mass is unchanged. Tried and not kept: the stack turned round
  // the edge towards i (more put-backs: 104 against 42 in 6 ms).
  template <class F>
  void for_each_ghost(const Vec3& xij, std::size_t i, std::size_t j, uint16_t body_j, F&& f) const {
    const Vec3& n = normal[j];
    const double s = sigma(xij, i, j, body_j);
    Vec3 r0 = xij;
    if (j < cap.size()) {
      const Vec3& e = cap[j];
      const double a = e.dot(xij);
      if (a > 0.0) r0 -= std::min(a, 0.5 * dx) * e;
    }
    for (int k = 1; k <= layers; ++k) f(Vec3(r0 + (s * (k - 0.5) * dx) * n));
  }
};

}  // namespace aortasph
