#include "physiology/orifice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace aortasph {

namespace {

// The disc rasterised as orifice_area describes it: cells `cell` wide, nc x nc, centred on the disc (the
// lower-left corner at lo in (u, v)); covered[j nc + i] = 1 for the cells within the cover radius of a
// projected particle.
struct Raster {
  Vec3 u, v;
  double cell = 0, lo = 0;
  int nc = 0;
  std::vector<uint8_t> covered;
};

Raster rasterise(const std::vector<Vec3>& points, double spacing, const Vec3& center, const Vec3& normal,
                 double radius) {
  Raster r;
  const Vec3 n = normal.normalized();
  r.u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  r.v = n.cross(r.u);
  r.cell = std::max(spacing / 8.0, 2.0 * radius / 2000.0);
  r.nc = static_cast<int>(std::ceil(2.0 * radius / r.cell));
  const int nc = r.nc;
  const double cell = r.cell;
  r.lo = -0.5 * nc * cell;  // grid centred on the disc
  const double lo = r.lo;
  r.covered.assign(static_cast<std::size_t>(nc) * nc, 0);
  const double rc = kOrificeCoverRadius * spacing, rc2 = rc * rc;
  for (const Vec3& p : points) {
    const double a = (p - center).dot(r.u), b = (p - center).dot(r.v);
    if (std::hypot(a, b) > radius + rc) continue;
    const int i0 = std::max(0, static_cast<int>(std::floor((a - rc - lo) / cell)));
    const int i1 = std::min(nc - 1, static_cast<int>(std::floor((a + rc - lo) / cell)));
    const int j0 = std::max(0, static_cast<int>(std::floor((b - rc - lo) / cell)));
    const int j1 = std::min(nc - 1, static_cast<int>(std::floor((b + rc - lo) / cell)));
    for (int j = j0; j <= j1; ++j) {
      const double y = lo + (j + 0.5) * cell - b;
      for (int i = i0; i <= i1; ++i) {
        const double x = lo + (i + 0.5) * cell - a;
        if (x * x + y * y <= rc2) r.covered[static_cast<std::size_t>(j) * nc + i] = 1;
      }
    }
  }
  return r;
}

}  // namespace

double orifice_area(const std::vector<Vec3>& points, double spacing, const Vec3& center, const Vec3& normal,
                    double radius) {
  if (!(radius > 0) || !(spacing > 0)) return 0.0;
  const Raster r = rasterise(points, spacing, center, normal, radius);
  std::size_t open = 0;
  for (int j = 0; j < r.nc; ++j)
    for (int i = 0; i < r.nc; ++i) {
      const double x = r.lo + (i + 0.5) * r.cell, y = r.lo + (j + 0.5) * r.cell;
      if (x * x + y * y <= radius * radius && !r.covered[static_cast<std::size_t>(j) * r.nc + i]) ++open;
    }
  return static_cast<double>(open) * r.cell * r.cell;
}

OrificeRegions orifice_regions(const std::vector<Vec3>& points, double spacing, const Vec3& center,
                               const Vec3& normal, double radius, double central_radius,
                               const std::vector<Vec3>& commissures) {
  OrificeRegions out;
  out.commissural.assign(commissures.size(), 0.0);
  if (!(radius > 0) || !(spacing > 0)) return out;
  const Raster r = rasterise(points, spacing, center, normal, radius);
  // Unit directions of the commissures in the disc's plane (u, v).
  std::vector<std::pair<double, double>> dir;
  for (const Vec3& c : commissures) {
    const double a = (c - center).dot(r.u), b = (c - center).dot(r.v), l = std::hypot(a, b);
    dir.emplace_back(l > 0 ? a / l : 1.0, l > 0 ? b / l : 0.0);
  }
  std::size_t open = 0, central = 0;
  std::vector<std::size_t> per(commissures.size(), 0);
  for (int j = 0; j < r.nc; ++j)
    for (int i = 0; i < r.nc; ++i) {
      const double x = r.lo + (i + 0.5) * r.cell, y = r.lo + (j + 0.5) * r.cell, rr = x * x + y * y;
      if (rr > radius * radius || r.covered[static_cast<std::size_t>(j) * r.nc + i]) continue;
      ++open;
      if (rr < central_radius * central_radius || dir.empty()) {
        ++central;
        continue;
      }
      // The nearest commissure by angle: the largest cosine (the first one on ties).
      std::size_t best = 0;
      double best_cos = -2.0;
      for (std::size_t k = 0; k < dir.size(); ++k) {
        const double c = x * dir[k].first + y * dir[k].second;
        if (c > best_cos) {
          best_cos = c;
          best = k;
        }
      }
      ++per[best];
    }
  const double a = r.cell * r.cell;
  out.total = static_cast<double>(open) * a;
  out.central = static_cast<double>(central) * a;
  for (std::size_t k = 0; k < per.size(); ++k) out.commissural[k] = static_cast<double>(per[k]) * a;
  return out;
}

}  // namespace aortasph
