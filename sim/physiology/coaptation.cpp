#include "physiology/coaptation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "core/neighbors.hpp"

namespace aortasph {

CoaptationStats coaptation_stats(const std::vector<Vec3>& points, const std::vector<int>& leaf, int leaflets,
                                 const Vec3& point, const Vec3& axis_in, double distance,
                                 double central_radius, double bin) {
  const Vec3 axis = axis_in.normalized();
  const std::size_t n = points.size();
  std::vector<double> z(n), r(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 rel = points[i] - point;
    z[i] = rel.dot(axis);
    r[i] = (rel - z[i] * axis).norm();
  }
  const int nl = leaflets;
  auto pair_index = [&](int a, int b) {
    if (a > b) std::swap(a, b);
    return static_cast<std::size_t>(a * nl - a * (a + 1) / 2 + (b - a - 1));
  };
  const std::size_t pairs = static_cast<std::size_t>(nl * (nl - 1) / 2);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> rmin(pairs, inf), rmax(pairs, -inf);
  // Per pair, per radial bin: the z range of its contact particles (ordered map: the median below does not
  // depend on the visiting order).
  std::vector<std::map<long, std::pair<double, double>>> bins(pairs);
  double czmin = inf, czmax = -inf, top = -inf;
  std::vector<double> top_of(static_cast<std::size_t>(nl), -inf);
  NeighborSearch nb;
  nb.build(points, distance);
  auto mark = [&](std::size_t p, std::size_t i) {
    rmin[p] = std::min(rmin[p], r[i]);
    rmax[p] = std::max(rmax[p], r[i]);
    const long b = static_cast<long>(std::floor(r[i] / bin));
    auto [it, fresh] = bins[p].try_emplace(b, z[i], z[i]);
    if (!fresh) {
      it->second.first = std::min(it->second.first, z[i]);
      it->second.second = std::max(it->second.second, z[i]);
    }
    if (r[i] < central_radius) {
      czmin = std::min(czmin, z[i]);
      czmax = std::max(czmax, z[i]);
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (r[i] < central_radius) {
      top = std::max(top, z[i]);
      top_of[static_cast<std::size_t>(leaf[i])] = std::max(top_of[static_cast<std::size_t>(leaf[i])], z[i]);
    }
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = nb.index()[k];
      if (j <= i || leaf[j] == leaf[i]) continue;
      const std::size_t p = pair_index(leaf[i], leaf[j]);
      mark(p, i);
      mark(p, j);
    }
  }
  CoaptationStats c;
  for (std::size_t p = 0; p < pairs; ++p) {
    std::vector<double> extent;
    for (const auto& [b, zr] : bins[p]) extent.push_back(zr.second - zr.first);
    double h = 0.0;
    if (!extent.empty()) {
      std::sort(extent.begin(), extent.end());
      const std::size_t m = extent.size();
      h = m % 2 ? extent[m / 2] : 0.5 * (extent[m / 2 - 1] + extent[m / 2]);
    }
    c.height.push_back(h);
    c.length.push_back(rmax[p] >= rmin[p] ? rmax[p] - rmin[p] : 0.0);
  }
  c.central_height = czmax >= czmin ? czmax - czmin : 0.0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.effective_height = std::isfinite(top) ? top : nan;
  for (double t : top_of) c.effective_per_leaflet.push_back(std::isfinite(t) ? t : nan);
  return c;
}

}  // namespace aortasph
