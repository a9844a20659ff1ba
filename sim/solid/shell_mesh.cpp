#include "solid/shell_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "solid/shell.hpp"

namespace aortasph {

namespace {

// A uniform grid of cells of side `cell` over the points, for the searches within one cell's reach.
class CellGrid {
 public:
  CellGrid(const std::vector<Vec3>& X, double cell) : inv_(1.0 / cell) {
    for (uint32_t i = 0; i < X.size(); ++i) cells_[key(X[i])].push_back(i);
  }
  // Calls f(m) for every point in the 27 cells round p's cell (in a fixed order).
  template <class F>
  void around(const Vec3& p, F&& f) const {
    const auto [cx, cy, cz] = key(p);
    for (long dz = -1; dz <= 1; ++dz)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dx = -1; dx <= 1; ++dx) {
          const auto it = cells_.find({cx + dx, cy + dy, cz + dz});
          if (it == cells_.end()) continue;
          for (uint32_t m : it->second) f(m);
        }
  }

 private:
  using Key = std::tuple<long, long, long>;
  Key key(const Vec3& p) const {
    return {std::lround(std::floor(p.x() * inv_)), std::lround(std::floor(p.y() * inv_)),
            std::lround(std::floor(p.z() * inv_))};
  }
  double inv_;
  std::map<Key, std::vector<uint32_t>> cells_;
};

Triangle sorted(Triangle t) {
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace

std::vector<Triangle> triangulate_sheet(const std::vector<Vec3>& X, const std::vector<Vec3>& N,
                                        double max_edge) {
  std::vector<Triangle> out;
  if (X.size() < 3 || !(max_edge > 0.0)) return out;
  const double L2 = max_edge * max_edge;
  constexpr double kTie = 1e-7;  // relative: points this close to the circumsphere are on it
  const CellGrid grid(X, max_edge);
  std::vector<uint32_t> near, on;
  for (uint32_t i = 0; i < X.size(); ++i) {
    // Neighbours within max_edge of higher index: i is the lowest vertex of the triangles it starts.
    near.clear();
    grid.around(X[i], [&](uint32_t m) {
      if (m > i && (X[m] - X[i]).squaredNorm() <= L2) near.push_back(m);
    });
    std::sort(near.begin(), near.end());
    for (std::size_t a = 0; a < near.size(); ++a)
      for (std::size_t b = a + 1; b < near.size(); ++b) {
        const uint32_t j = near[a], k = near[b];
        if ((X[k] - X[j]).squaredNorm() > L2) continue;
        const Vec3 u = X[j] - X[i], v = X[k] - X[i], n = u.cross(v);
        const double n2 = n.squaredNorm();
        if (!(n2 > 1e-12 * u.squaredNorm() * v.squaredNorm())) continue;  // (nearly) collinear
        // Circumcentre of the triangle, in its plane.
        const Vec3 c = X[i] + (u.squaredNorm() * v.cross(n) + v.squaredNorm() * n.cross(u)) / (2.0 * n2);
        const double R = (c - X[i]).norm();
        if (R > max_edge) continue;
        bool empty = true;
        on.assign({i, j, k});
        grid.around(c, [&](uint32_t m) {
          if (!empty || m == i || m == j || m == k) return;
          const double d = (X[m] - c).norm();
          if (d < R * (1.0 - kTie))
            empty = false;
          else if (d <= R * (1.0 + kTie))
            on.push_back(m);
        });
        if (!empty) continue;
        if (on.size() > 3) {
          // Cocircular: keep only the fan from the lowest index, in angular order round the circle.
          const Vec3 e1 = u.normalized(), e2 = n.cross(u).normalized();
          std::vector<std::pair<double, uint32_t>> ring;
          for (uint32_t m : on) ring.emplace_back(std::atan2((X[m] - c).dot(e2), (X[m] - c).dot(e1)), m);
          std::sort(ring.begin(), ring.end());
          const auto lowest = std::min_element(
              ring.begin(), ring.end(), [](const auto& p, const auto& q) { return p.second < q.second; });
          std::rotate(ring.begin(), lowest, ring.end());
          const Triangle self = sorted({i, j, k});
          bool in_fan = false;
          for (std::size_t t = 1; t + 1 < ring.size() && !in_fan; ++t)
            in_fan = sorted({ring[0].second, ring[t].second, ring[t + 1].second}) == self;
          if (!in_fan) continue;
        }
        if (n.dot(N[i] + N[j] + N[k]) >= 0.0)
          out.push_back({i, j, k});
        else
          out.push_back({i, k, j});
      }
  }
  return out;
}

ShellSheets::ShellSheets(const Shells& shells, const std::vector<uint16_t>& body, double max_edge) {
  std::map<uint16_t, std::vector<uint32_t>> slots;  // by body, ascending slot
  for (uint32_t s = 0; s < shells.size(); ++s) slots[body[s]].push_back(s);
  for (const auto& [b, of_body] : slots) {
    std::vector<Vec3> X, N;
    for (uint32_t s : of_body) {
      X.push_back(shells.reference(s));
      N.push_back(shells.reference_normal(s));
    }
    for (const Triangle& t : triangulate_sheet(X, N, max_edge)) {
      triangles_.push_back({of_body[t[0]], of_body[t[1]], of_body[t[2]]});
      body_.push_back(b);
    }
  }
}

}  // namespace aortasph
