#include "rigid/contact_dem.hpp"

#include <cmath>

#include "core/parallel.hpp"

namespace aortasph {

Vec3 contact_force(const ContactParams& c, const Vec3& xij, const Vec3& vij) {
  const double r = xij.norm();
  const double overlap = c.distance - r;
  if (overlap <= 0.0 || r <= 0.0) return Vec3::Zero();
  const Vec3 n = xij / r;
  const double vn = vij.dot(n);
  // eqs. (23), (24): spring along n, damper against the normal approach speed; never attractive.
  const double fn = std::max(c.k * overlap - c.eta * vn, 0.0);
  Vec3 f = fn * n;
  // eq. (25), capped by Coulomb friction.
  if (c.shear > 0.0) {
    const Vec3 vt = vij - vn * n;
    Vec3 ft = -c.shear * vt;
    const double cap = c.friction * fn;
    const double ftn = ft.norm();
    if (ftn > cap) ft *= cap / ftn;
    f += ft;
  }
  return f;
}

void contact_forces(const Particles& P, const NeighborSearch& nb, const ContactParams& c,
                    std::vector<Vec3>& f, std::vector<Vec3>& moment) {
  if (c.k <= 0.0) return;
  const auto& idx = nb.index();
  const double d2 = c.distance * c.distance;
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (fluid_like(P.kind[i]) || P.kind[i] == Kind::Wall) return;  // walls never move: no force needed
    Vec3 sum = Vec3::Zero(), mom = Vec3::Zero();
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      if (fluid_like(P.kind[j]) || P.body[j] == P.body[i]) continue;
      if (c.skip_shells && (P.kind[i] == Kind::Shell || P.kind[j] == Kind::Shell)) continue;
      const Vec3 xij = P.x[i] - P.x[j];
      if (xij.squaredNorm() >= d2) continue;
      const Vec3 fij = contact_force(c, xij, P.v[i] - P.v[j]);
      sum += fij;
      mom += (-0.5 * xij).cross(fij);
    }
    f[i] += sum;
    moment[i] += mom;
  });
}

}  // namespace aortasph
