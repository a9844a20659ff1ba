#include "physiology/orifice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace aortasph {

double orifice_area(const std::vector<Vec3>& points, double spacing, const Vec3& center, const Vec3& normal,
                    double radius) {
  if (!(radius > 0) || !(spacing > 0)) return 0.0;
  const Vec3 n = normal.normalized();
  const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 v = n.cross(u);
  const double cell = std::max(spacing / 8.0, 2.0 * radius / 2000.0);
  const int nc = static_cast<int>(std::ceil(2.0 * radius / cell));
  const double lo = -0.5 * nc * cell;  // grid centred on the disc
  std::vector<uint8_t> covered(static_cast<std::size_t>(nc) * nc, 0);
  const double rc = kOrificeCoverRadius * spacing, rc2 = rc * rc;
  for (const Vec3& p : points) {
    const double a = (p - center).dot(u), b = (p - center).dot(v);
    if (std::hypot(a, b) > radius + rc) continue;
    const int i0 = std::max(0, static_cast<int>(std::floor((a - rc - lo) / cell)));
    const int i1 = std::min(nc - 1, static_cast<int>(std::floor((a + rc - lo) / cell)));
    const int j0 = std::max(0, static_cast<int>(std::floor((b - rc - lo) / cell)));
    const int j1 = std::min(nc - 1, static_cast<int>(std::floor((b + rc - lo) / cell)));
    for (int j = j0; j <= j1; ++j) {
      const double y = lo + (j + 0.5) * cell - b;
      for (int i = i0; i <= i1; ++i) {
        const double x = lo + (i + 0.5) * cell - a;
        if (x * x + y * y <= rc2) covered[static_cast<std::size_t>(j) * nc + i] = 1;
      }
    }
  }
  std::size_t open = 0;
  for (int j = 0; j < nc; ++j)
    for (int i = 0; i < nc; ++i) {
      const double x = lo + (i + 0.5) * cell, y = lo + (j + 0.5) * cell;
      if (x * x + y * y <= radius * radius && !covered[static_cast<std::size_t>(j) * nc + i]) ++open;
    }
  return static_cast<double>(open) * cell * cell;
}

}  // namespace aortasph
