// Periodic axes of the domain (docs/scenes.md, domain.periodic). Along a periodic axis the domain's length is
// the period: a particle that leaves through one face re-enters through the other, and every pair distance is
// the nearest image (the minimum-image convention of molecular dynamics: Allen & Tildesley 1987, "Computer
// Simulation of Liquids", sec. 1.5.2). Used by the neighbour search, the fluid's and the walls' pair sums and
// the integrator; the periodic flows of the validation (Poiseuille between plates, Morris, Fox & Zhu 1997;
// the Taylor-Green vortex) need nothing else. Elastic and rigid bodies and open boundaries are not allowed in
// a periodic scene (the loader refuses them), so their pair loops stay as they are.
#pragma once

#include <cmath>

#include "scene.hpp"

namespace aortasph {

struct Periodic {
  bool on[3] = {false, false, false};
  Vec3 lo = Vec3::Zero();
  Vec3 len = Vec3::Ones();
  bool any = false;

  Periodic() = default;
  Periodic(const Box& domain, const std::array<bool, 3>& axes)
      : lo(domain.min), len(domain.max - domain.min) {
    for (int a = 0; a < 3; ++a) {
      on[a] = axes[a];
      any = any || on[a];
    }
  }
  // The nearest image of a separation d = x_i - x_j.
  Vec3 image(Vec3 d) const {
    for (int a = 0; a < 3; ++a)
      if (on[a]) d[a] -= len[a] * std::round(d[a] / len[a]);
    return d;
  }
  // v without its components along the periodic axes. Along a periodic axis there is no hydrostatic
  // balance: a body force there drives a flow (plane or pipe Poiseuille) against a pressure that is the same
  // at both faces, so the hydrostatic start and the delta-SPH's hydrostatic correction use only the rest.
  Vec3 across(Vec3 v) const {
    for (int a = 0; a < 3; ++a)
      if (on[a]) v[a] = 0.0;
    return v;
  }
  // x moved back into [lo, lo + len) along the periodic axes.
  void wrap(Vec3& x) const {
    for (int a = 0; a < 3; ++a) {
      if (!on[a]) continue;
      x[a] -= len[a] * std::floor((x[a] - lo[a]) / len[a]);
      if (x[a] >= lo[a] + len[a]) x[a] = lo[a];  // rounding of a particle a hair below lo
    }
  }
};

}  // namespace aortasph
