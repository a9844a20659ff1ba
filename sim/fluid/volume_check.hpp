// Whether the fluid's particles stand where their densities say (a diagnostic, not a model): for each fluid
// particle whose kernel support holds only fluid (fluid proper and open-boundary buffers), the summation
// density sum_j m_j W_ij (Monaghan 1992, Annu. Rev. Astron. Astrophys. 30:543, eq. 2.8; self included) over
// its continuity density rho_i (paper eq. 12). On the initial lattice it is sum_j W_ij dx^3 (0.997 for the
// cubic spline at h = 1.3 dx, docs/validation.md "Kernel"); it stays there while eq. 12 follows the
// particles. Eq. 12 never looks at where the particles stand, so a drift that moves them apart while their
// densities hold (the shift beside the leaflets that stop 50 found: 12 % in the physio scene's aorta) is seen
// by no pressure and by no other diagnostic; this one reads 1 / 1.12 there. At a free surface the support
// is not full and the ratio falls below 1 for that reason: it is meant for confined flows. Disorder raises
// it too, at unchanged volume: a lattice whose particles are shaken by 0.05 / 0.15 dx rms reads 1.003 / 1.021
// at h = 1.2 dx (lattice 1.0008; test [fluid][diagnostics] "a shaken lattice"), so a reading above 1 in a
// stirred flow is no proof of compaction; one below the lattice's value is thinning (docs/validation.md,
// stop 52).
#pragma once

#include <cstddef>

#include "core/kernel.hpp"
#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "core/periodic.hpp"

namespace aortasph {

struct VolumeCheck {
  double mean = 0.0;          // mean of sum_j m_j W_ij / rho_i over the particles counted; NaN if none
  std::size_t particles = 0;  // the fluid particles whose support holds only fluid
};

// lists: Verlet lists that hold every pair of P closer than the kernel's support (pairs beyond it are
// skipped), or null: then it builds its own cell lists at the support. The sums run in a fixed order, so the
// result is the same for any thread count.
VolumeCheck fluid_volume_check(const Particles& P, const CubicSpline& kernel, const Periodic& periodic,
                               const NeighborSearch* lists = nullptr);

}  // namespace aortasph
