#include "io/probes.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include "core/neighbors.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "geometry/shapes.hpp"
#include "physiology/coaptation.hpp"
#include "physiology/orifice.hpp"

namespace aortasph {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Open-boundary buffer particles stand outside the domain: probes of bodies, energy and momentum leave them
// out.
bool is_buffer(Kind k) {
  return k == Kind::Inflow || k == Kind::Outflow;
}

struct Sum3 {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  double m = 0.0;
  Sum3 operator+(const Sum3& o) const { return {a + o.a, b + o.b, m + o.m}; }
};

// 1 for the listed bodies, by body index.
std::vector<char> body_mask(const World& world, const std::vector<int>& bodies) {
  std::vector<char> in_set(world.bodies().size(), 0);
  for (int b : bodies) in_set[b] = 1;
  return in_set;
}

struct GapStats {
  double min = 0.0;        // smallest distance between particles of different bodies, capped at 2 spacings
  long long overlaps = 0;  // pairs of particles of different bodies closer than half a spacing
};

// How close the listed bodies come to each other: for leaflets, whether contact keeps them apart (a leaflet
// passing through another must bring particles of both closer than half a spacing somewhere). Pairs within
// two spacings from a NeighborSearch over the bodies' particles; min and counts do not depend on the visiting
// order.
GapStats body_gap(const World& world, const std::vector<int>& bodies) {
  const Particles& P = world.particles();
  const double dx = world.scene().spacing, reach = 2.0 * dx, half2 = 0.25 * dx * dx;
  const std::vector<char> in_set = body_mask(world, bodies);
  std::vector<Vec3> x;
  std::vector<int> body;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (in_set[P.body[i]]) {
      x.push_back(P.x[i]);
      body.push_back(P.body[i]);
    }
  NeighborSearch nb;
  nb.build(x, reach);
  GapStats g;
  double min2 = reach * reach;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = nb.index()[k];
      if (j <= i || body[j] == body[i]) continue;
      const double r2 = (x[j] - x[i]).squaredNorm();
      min2 = std::min(min2, r2);
      if (r2 < half2) ++g.overlaps;
    }
  g.min = std::sqrt(min2);
  return g;
}

// The leading edge of the continuous fluid along `axis` (an `extent` probe with "stat": "extent",
// docs/scenes.md): the particles of the listed bodies inside the region are linked when closer than `link`
// (by default the kernel support 2h: farther apart, two particles exchange no force, so a cluster cut off at
// that distance moves on its own, under gravity only: a droplet or a spray). The answer is the largest
// coordinate of the largest cluster (most particles; among equal largest clusters, the furthest), plus half a
// spacing: the edge of the fluid the particles stand for, not the last particle's centre. Clusters
// by union-find over the pairs of a NeighborSearch, visited in its fixed order; the result is a count and a
// maximum, so it does not depend on the visiting order or the thread count. NaN over no particle.
double continuous_extent(const World& world, const Probe& pr) {
  const Particles& P = world.particles();
  const std::vector<char> in_set = body_mask(world, pr.bodies);
  const double link = pr.link > 0.0 ? pr.link : world.kernel().support;
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (in_set[P.body[i]] && !is_buffer(P.kind[i]) && (!pr.region || pr.region->contains(P.x[i])))
      x.push_back(P.x[i]);
  if (x.empty()) return kNaN;
  std::vector<uint32_t> parent(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) parent[i] = static_cast<uint32_t>(i);
  auto root = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];  // path halving
    return i;
  };
  NeighborSearch nb;
  nb.build(x, link);
  for (std::size_t i = 0; i < x.size(); ++i)
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t a = root(static_cast<uint32_t>(i)), b = root(nb.index()[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<std::size_t> count(x.size(), 0);
  std::vector<double> top(x.size(), -std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const uint32_t r = root(static_cast<uint32_t>(i));
    ++count[r];
    top[r] = std::max(top[r], x[i][pr.axis]);
  }
  std::size_t best_count = 0;
  double best = kNaN;
  for (std::size_t r = 0; r < x.size(); ++r)
    if (count[r] > best_count || (count[r] == best_count && count[r] > 0 && top[r] > best)) {
      best_count = count[r];
      best = top[r];
    }
  // A particle stands for the cube of side dx around it: the fluid's edge is half a spacing beyond the last
  // particle's centre (as where World sets the free surface of a fluid body at rest), so a column of side a
  // measures a at t = 0, at any resolution.
  return best + 0.5 * world.scene().spacing;
}

// Largest eigenvalue of the Green-Lagrange strain E = (F^T F - I) / 2 (paper eq. 15).
double largest_principal_strain(const Eigen::Matrix3d& F) {
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(E, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

// Coaptation of the listed leaflets (physiology/coaptation.hpp; docs/valve-metrics.md): contact within the
// probe's distance, heights per radial bin one spacing wide.
CoaptationStats coaptation(const World& world, const Probe& pr) {
  const Particles& P = world.particles();
  std::vector<int> slot(world.bodies().size(), -1);
  for (std::size_t k = 0; k < pr.bodies.size(); ++k) slot[pr.bodies[k]] = static_cast<int>(k);
  std::vector<Vec3> x;
  std::vector<int> leaf;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (slot[P.body[i]] >= 0) {
      x.push_back(P.x[i]);
      leaf.push_back(slot[P.body[i]]);
    }
  return coaptation_stats(x, leaf, static_cast<int>(pr.bodies.size()), pr.point, pr.normal, pr.distance,
                          pr.central_radius, world.scene().spacing);
}

// The unit vectors (u, v) of the plane normal to n, as orifice_area takes them (sim/physiology/orifice.cpp).
void plane_frame(const Vec3& normal, Vec3& u, Vec3& v) {
  const Vec3 n = normal.normalized();
  u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  v = n.cross(u);
}

// Angle in (-pi, pi].
double wrap_angle(double a) {
  while (a > std::numbers::pi) a -= 2.0 * std::numbers::pi;
  while (a <= -std::numbers::pi) a += 2.0 * std::numbers::pi;
  return a;
}

// Points binned in cubic cells of side `cell` (sorted by cell key, then by index: deterministic), for the
// distance from a point to the nearest of them within one cell side.
class PointGrid {
 public:
  PointGrid(std::vector<Vec3> pts, double cell) : pts_(std::move(pts)), cell_(cell) {
    for (std::size_t i = 0; i < pts_.size(); ++i) keys_.emplace_back(key(cell_of(pts_[i])), i);
    std::sort(keys_.begin(), keys_.end());
  }
  // min(cap, the distance from x to the nearest point); cap <= cell.
  double nearest(const Vec3& x, double cap) const {
    double best2 = cap * cap;
    for_each_near(x, [&](std::size_t k) { best2 = std::min(best2, (pts_[k] - x).squaredNorm()); });
    return std::sqrt(best2);
  }
  // Calls f(k) for every point k closer to x than r (r <= cell), in a fixed order (the 27 cells around x,
  // then the points of each cell in the order they were given).
  template <class F>
  void for_each_within(const Vec3& x, double r, F&& f) const {
    const double r2 = r * r;
    for_each_near(x, [&](std::size_t k) {
      if ((pts_[k] - x).squaredNorm() < r2) f(k);
    });
  }

 private:
  // Calls f(k) for every point k of the 27 cells around x's, cells in a fixed order.
  template <class F>
  void for_each_near(const Vec3& x, F&& f) const {
    const std::array<long, 3> c = cell_of(x);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const uint64_t k = key({c[0] + dx, c[1] + dy, c[2] + dz});
          auto it = std::lower_bound(keys_.begin(), keys_.end(), std::pair<uint64_t, std::size_t>(k, 0));
          for (; it != keys_.end() && it->first == k; ++it) f(it->second);
        }
  }
  std::array<long, 3> cell_of(const Vec3& x) const {
    return {static_cast<long>(std::floor(x.x() / cell_)), static_cast<long>(std::floor(x.y() / cell_)),
            static_cast<long>(std::floor(x.z() / cell_))};
  }
  static uint64_t key(const std::array<long, 3>& c) {
    const uint64_t off = 1u << 20, mask = (1u << 21) - 1;
    return ((static_cast<uint64_t>(c[0] + off) & mask) << 42) |
           ((static_cast<uint64_t>(c[1] + off) & mask) << 21) | (static_cast<uint64_t>(c[2] + off) & mask);
  }
  std::vector<Vec3> pts_;
  double cell_;
  std::vector<std::pair<uint64_t, std::size_t>> keys_;
};

// The particles of the listed bodies: current (or, reference, t = 0) positions.
std::vector<Vec3> positions_of(const Particles& P, const std::vector<char>& in_set, bool reference) {
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (in_set[P.body[i]] && !is_buffer(P.kind[i])) x.push_back(reference ? P.x0[i] : P.x[i]);
  return x;
}

void add_columns(std::vector<std::string>& cols, const std::string& name,
                 std::initializer_list<const char*> fields) {
  for (const char* f : fields) cols.push_back(name + "." + f);
}

// Id of the particle of `body` nearest `point` at t = 0 (lowest id on ties): the particle a `point` or
// `displacement` probe follows. Probe k names the probe in the error.
uint32_t nearest_particle_id(const Particles& P, int body, const Vec3& point, std::size_t k,
                             const std::string& name) {
  double best = std::numeric_limits<double>::max();
  uint32_t id = std::numeric_limits<uint32_t>::max();
  bool found = false;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.body[i] != body) continue;
    const double d = (P.x0[i] - point).squaredNorm();
    if (d < best || (d == best && P.id[i] < id)) {
      best = d;
      id = P.id[i];
      found = true;
    }
  }
  if (!found) throw SetupError("probes[" + std::to_string(k) + "] '" + name + "': body has no particle");
  return id;
}

}  // namespace

double percentile_nearest_rank(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t rank = static_cast<std::size_t>(std::ceil(q / 100.0 * static_cast<double>(v.size())));
  const std::size_t k = std::min(v.size() - 1, rank > 0 ? rank - 1 : 0);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

std::vector<std::string> stress_body_columns(std::size_t b) {
  const std::string k = std::to_string(b);
  return {k + ".max", k + ".p95", k + ".max_height", k + ".max_s"};
}

std::vector<std::string> coaptation_columns(std::size_t leaflets, bool per_leaflet) {
  std::vector<std::string> cols;
  for (std::size_t a = 0; a < leaflets; ++a)
    for (std::size_t b = a + 1; b < leaflets; ++b) {
      const std::string pair = std::to_string(a) + "_" + std::to_string(b);
      cols.push_back("height_" + pair);
      cols.push_back("length_" + pair);
    }
  cols.push_back("central_height");
  cols.push_back("effective_height");
  if (per_leaflet)
    for (std::size_t a = 0; a < leaflets; ++a) cols.push_back("effective_height_" + std::to_string(a));
  return cols;
}

namespace {

// The mean pressure over a sensor's face (issue 20: the wall sensors of Lobovsky et al. 2014): the disc of
// centre c, unit normal n and radius R, sampled at the 29 points of a square grid of pitch R/3 inside it,
// each the Shepard-normalised interpolation of the fluid pressure (eq. 4 divided by sum V_j W_ij); a point
// with no fluid particle within the kernel's support (dry) reads 0. Serial over the particles within R + 2h
// of c, in index order: the same sum for any thread count.
double sensor_pressure(const World& world, const Vec3& c, const Vec3& n, double R) {
  const Particles& P = world.particles();
  const CubicSpline& K = world.kernel();
  const double reach = R + K.support;
  Vec3 u, v;
  perpendicular_frame(n, u, v);
  std::vector<Vec3> pts;
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      if (i * i + j * j <= 9) pts.push_back(c + (R / 3.0) * (i * u + j * v));
  std::vector<double> pw(pts.size(), 0.0), w(pts.size(), 0.0);
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid || (P.x[i] - c).squaredNorm() > reach * reach) continue;
    const double vol = P.m[i] / P.rho[i];
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const double W = K.W((P.x[i] - pts[k]).norm()) * vol;
      pw[k] += P.p[i] * W;
      w[k] += W;
    }
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < pts.size(); ++k)
    if (w[k] > 0.0) sum += pw[k] / w[k];
  return sum / static_cast<double>(pts.size());
}

}  // namespace

ProbeSet::ProbeSet(const Scene& scene, const World& world) : probes_(scene.probes) {
  const Particles& P = world.particles();
  tracked_id_.assign(probes_.size(), 0);
  cusp_frames_.assign(probes_.size(), {});
  eligible_.assign(probes_.size(), {});
  for (std::size_t k = 0; k < probes_.size(); ++k) {
    const Probe& pr = probes_[k];
    switch (pr.type) {
      case ProbeType::Extent:
      case ProbeType::Pressure:
      case ProbeType::FlowRate:
        columns_.push_back(pr.name);
        break;
      case ProbeType::BodyState:
        add_columns(columns_, pr.name, {"x", "y", "z", "vx", "vy", "vz", "px", "py", "pz"});
        if (world.bodies()[pr.body].rigid >= 0)
          add_columns(columns_, pr.name, {"wx", "wy", "wz", "qw", "qx", "qy", "qz"});
        break;
      case ProbeType::Point: {
        add_columns(columns_, pr.name, {"ux", "uy", "uz", "vx", "vy", "vz", "stress"});
        tracked_id_[k] = nearest_particle_id(P, pr.body, pr.reference, k, pr.name);
        break;
      }
      case ProbeType::Energy:
        add_columns(columns_, pr.name, {"kinetic", "potential", "elastic", "total"});
        break;
      case ProbeType::Momentum:
        add_columns(columns_, pr.name, {"px", "py", "pz", "lx", "ly", "lz"});
        break;
      case ProbeType::OpenBoundary:
        add_columns(columns_, pr.name,
                    {"volume_in", "volume_out", "volume_inside", "prescribed_rate", "mass_in", "mass_out",
                     "mass_inside"});
        // Then, per open boundary N (issue 17): N.flow, N.pressure.
        for (const OpenBoundarySpec& b : scene.open_boundaries)
          for (const char* what : {".flow", ".pressure"}) columns_.push_back(pr.name + "." + b.name + what);
        break;
      case ProbeType::OrificeArea:
        columns_.push_back(pr.name);
        break;
      case ProbeType::Stress:
        add_columns(columns_, pr.name, {"max", "mean", "p95", "strain_max"});
        if (pr.per_body) {
          // Per listed body b: max, p95 and the peak particle's place (stress_body_columns).
          for (std::size_t b = 0; b < pr.bodies.size(); ++b)
            for (const std::string& c : stress_body_columns(b)) columns_.push_back(pr.name + "." + c);
          // The cusp frames at t = 0: the angle of the body's centroid about the axis, and its particles'
          // angular span about that angle (the cusp from one commissure to the other).
          Vec3 u, v;
          plane_frame(pr.normal, u, v);
          for (int body : pr.bodies) {
            std::vector<char> one(world.bodies().size(), 0);
            one[body] = 1;
            const std::vector<Vec3> x0 = positions_of(P, one, true);
            Vec3 c = Vec3::Zero();
            for (const Vec3& x : x0) c += x;
            if (!x0.empty()) c /= static_cast<double>(x0.size());
            CuspFrame f;
            f.theta_c = std::atan2((c - pr.point).dot(v), (c - pr.point).dot(u));
            f.phi_min = std::numeric_limits<double>::infinity();
            f.phi_max = -f.phi_min;
            for (const Vec3& x : x0) {
              const double phi =
                  wrap_angle(std::atan2((x - pr.point).dot(v), (x - pr.point).dot(u)) - f.theta_c);
              f.phi_min = std::min(f.phi_min, phi);
              f.phi_max = std::max(f.phi_max, phi);
            }
            cusp_frames_[k].push_back(f);
          }
        }
        break;
      case ProbeType::GapArea:
        add_columns(columns_, pr.name, {"total", "central", "commissural"});
        for (std::size_t c = 0; c < pr.commissures.size(); ++c)
          columns_.push_back(pr.name + ".commissural_" + std::to_string(c));
        break;
      case ProbeType::WallDistance: {
        columns_.push_back(pr.name + ".min");
        for (std::size_t b = 0; b < pr.bodies.size(); ++b)
          columns_.push_back(pr.name + ".min_" + std::to_string(b));
        // The leaflet particles farther than `exclude` from the walls at t = 0 (the attachment left out).
        const std::vector<char> walls = body_mask(world, pr.walls), leaflets = body_mask(world, pr.bodies);
        const double cell = std::max(pr.exclude, world.scene().spacing);
        const PointGrid grid(positions_of(P, walls, true), cell);
        for (std::size_t i = 0; i < P.size(); ++i)
          if (leaflets[P.body[i]] && !is_buffer(P.kind[i]) &&
              (pr.exclude <= 0.0 || grid.nearest(P.x0[i], pr.exclude) >= pr.exclude))
            eligible_[k].push_back(P.id[i]);
        std::sort(eligible_[k].begin(), eligible_[k].end());
        break;
      }
      case ProbeType::Gap:
        add_columns(columns_, pr.name, {"min", "overlaps"});
        break;
      case ProbeType::MaxSpeed:
        columns_.push_back(pr.name);
        break;
      case ProbeType::Coaptation:
        for (const std::string& c : coaptation_columns(pr.bodies.size(), pr.per_body))
          columns_.push_back(pr.name + "." + c);
        break;
      case ProbeType::Displacement: {
        add_columns(columns_, pr.name, {"ux", "uy", "uz"});
        tracked_id_[k] = nearest_particle_id(P, pr.body, pr.point, k, pr.name);
        break;
      }
    }
  }
}

std::vector<double> ProbeSet::measure(const World& world) const {
  const Particles& P = world.particles();
  const std::size_t n = P.size();
  const Vec3 g = world.scene().gravity;
  std::vector<double> out;
  out.reserve(columns_.size());

  for (std::size_t k = 0; k < probes_.size(); ++k) {
    const Probe& pr = probes_[k];
    switch (pr.type) {
      case ProbeType::Extent: {
        if (pr.stat_extent) {
          out.push_back(continuous_extent(world, pr));
          break;
        }
        // Max (or min) coordinate over the bodies' particles inside the region: a water gauge or surge front.
        const std::vector<char> in_set = body_mask(world, pr.bodies);
        const double sign = pr.stat_max ? 1.0 : -1.0;
        const double best = parallel_reduce(
            n, -std::numeric_limits<double>::infinity(),
            [&](std::size_t i) {
              if (!in_set[P.body[i]] || is_buffer(P.kind[i]) || (pr.region && !pr.region->contains(P.x[i])))
                return -std::numeric_limits<double>::infinity();
              return sign * P.x[i][pr.axis];
            },
            [](double a, double b) { return std::max(a, b); });
        out.push_back(std::isfinite(best) ? sign * best : kNaN);
        break;
      }
      case ProbeType::Pressure: {
        // Shepard-normalised kernel interpolation of the fluid pressure, eq. (4) divided by sum V_j W_ij.
        const CubicSpline& K = world.kernel();
        if (pr.radius > 0.0) {
          out.push_back(sensor_pressure(world, pr.point, pr.normal, pr.radius));
          break;
        }
        struct PW {
          double pw = 0, w = 0;
        };
        const PW s = parallel_reduce(
            n, PW{},
            [&](std::size_t i) {
              if (P.kind[i] != Kind::Fluid) return PW{};
              const double W = K.W((P.x[i] - pr.point).norm()) * P.m[i] / P.rho[i];
              return PW{P.p[i] * W, W};
            },
            [](const PW& a, const PW& b) {
              return PW{a.pw + b.pw, a.w + b.w};
            });
        out.push_back(s.w > 0.0 ? s.pw / s.w : kNaN);
        break;
      }
      case ProbeType::BodyState: {
        if (const int r = world.bodies()[pr.body].rigid; r >= 0) {
          const RigidBody& b = world.rigid_bodies()[r];
          const Vec3 v = b.velocity(), w = b.omega();
          out.insert(out.end(), {b.com.x(), b.com.y(), b.com.z(), v.x(), v.y(), v.z(), b.P.x(), b.P.y(),
                                 b.P.z(), w.x(), w.y(), w.z(), b.q.w(), b.q.x(), b.q.y(), b.q.z()});
          break;
        }
        // Centre of mass, its velocity and the body's momentum.
        const Sum3 s = parallel_reduce(
            n, Sum3{},
            [&](std::size_t i) {
              if (P.body[i] != pr.body || is_buffer(P.kind[i])) return Sum3{};
              const double m = world.inertial_mass(i);
              return Sum3{m * P.x[i], m * P.v[i], m};
            },
            [](const Sum3& a, const Sum3& b) { return a + b; });
        const Vec3 c = s.m > 0 ? Vec3(s.a / s.m) : Vec3::Constant(kNaN);
        const Vec3 v = s.m > 0 ? Vec3(s.b / s.m) : Vec3::Constant(kNaN);
        for (int d = 0; d < 3; ++d) out.push_back(c[d]);
        for (int d = 0; d < 3; ++d) out.push_back(v[d]);
        for (int d = 0; d < 3; ++d) out.push_back(s.b[d]);
        break;
      }
      case ProbeType::Point: {
        std::size_t at = n;
        for (std::size_t i = 0; i < n && at == n; ++i)
          if (P.id[i] == tracked_id_[k]) at = i;
        if (at == n) {  // the particle left the domain
          for (int c = 0; c < 7; ++c) out.push_back(kNaN);
          break;
        }
        const Vec3 u = P.x[at] - P.x0[at];
        for (int d = 0; d < 3; ++d) out.push_back(u[d]);
        for (int d = 0; d < 3; ++d) out.push_back(P.v[at][d]);
        const long slot = world.solids().slot(at);  // von Mises stress: elastic particles only
        out.push_back(slot >= 0 ? world.solids().von_mises(static_cast<std::size_t>(slot)) : 0.0);
        break;
      }
      case ProbeType::Energy: {
        // Kinetic and gravitational potential energy of all moving particles (potential zero at the origin).
        // The fluid's compression energy is not counted.
        struct E {
          double kin = 0, pot = 0;
        };
        const E e = parallel_reduce(
            n, E{},
            [&](std::size_t i) {
              if (P.kind[i] == Kind::Wall || P.kind[i] == Kind::Rigid || is_buffer(P.kind[i])) return E{};
              const double m = world.inertial_mass(i);
              return E{0.5 * m * P.v[i].squaredNorm(), -m * g.dot(P.x[i])};
            },
            [](const E& a, const E& b) {
              return E{a.kin + b.kin, a.pot + b.pot};
            });
        // Rigid bodies: translation and rotation, eq. (21), and the potential of the centre of mass.
        double kin = e.kin, pot = e.pot;
        for (const RigidBody& b : world.rigid_bodies()) {
          kin += b.kinetic_energy();
          pot -= b.mass * g.dot(b.com);
        }
        // Elastic solids: sum_s V_s psi(E_s), eqs. (15)-(16), plus the hourglass springs' energy.
        // Shells: elastic and hourglass energy of the last update, plus the directors' spin energy.
        const double elastic = world.solids().elastic_energy(P) + world.shells().energy();
        kin += world.shells().rotational_energy();
        out.insert(out.end(), {kin, pot, elastic, kin + pot + elastic});
        break;
      }
      case ProbeType::Momentum: {
        const Sum3 t = parallel_reduce(
            n, Sum3{},
            [&](std::size_t i) {
              if (P.kind[i] == Kind::Wall || P.kind[i] == Kind::Rigid || is_buffer(P.kind[i])) return Sum3{};
              const Vec3 p = world.inertial_mass(i) * P.v[i];
              return Sum3{p, P.x[i].cross(p), 0.0};
            },
            [](const Sum3& a, const Sum3& b) { return a + b; });
        // Rigid bodies: P and, about the origin, com x P plus the spin L (eq. 20).
        Sum3 s = t;
        for (const RigidBody& b : world.rigid_bodies()) s = s + Sum3{b.P, b.com.cross(b.P) + b.L, 0.0};
        for (int d = 0; d < 3; ++d) out.push_back(s.a[d]);
        for (int d = 0; d < 3; ++d) out.push_back(s.b[d]);
        break;
      }
      case ProbeType::FlowRate: {
        // Volume flux through a disc: the fluid volume in a slab of thickness d = 2 spacings around the disc,
        // times its normal velocity, divided by d (a control-volume average of v.n over the slab).
        const double d = 2.0 * world.scene().spacing;
        const Vec3 nrm = pr.normal.normalized();
        const double q = parallel_reduce(
            n, 0.0,
            [&](std::size_t i) {
              if (P.kind[i] != Kind::Fluid) return 0.0;
              const Vec3 rel = P.x[i] - pr.point;
              const double axial = rel.dot(nrm);
              if (std::abs(axial) >= 0.5 * d || (rel - axial * nrm).norm() > pr.radius) return 0.0;
              return P.m[i] / P.rho[i] * P.v[i].dot(nrm);
            },
            [](double a, double b) { return a + b; });
        out.push_back(q / d);
        break;
      }
      case ProbeType::OpenBoundary: {
        // Cumulative volumes through the open boundaries (m / rho of each particle as it crossed a disc), the
        // fluid volume inside now (sum of m / rho over fluid particles, buffers excluded) and the prescribed
        // inflow rate now; then the same as masses. Volume balance: volume_in - volume_out = change of
        // volume_inside, up to the fluid's change of density (weakly compressible); mass balance: exact, up
        // to particles that leave the domain elsewhere.
        const OpenBoundaries& ob = world.open_boundaries();
        struct VM {
          double v = 0, m = 0;
        };
        const VM inside = parallel_reduce(
            n, VM{},
            [&](std::size_t i) {
              return P.kind[i] == Kind::Fluid ? VM{P.m[i] / P.rho[i], P.m[i]} : VM{};
            },
            [](const VM& a, const VM& b) {
              return VM{a.v + b.v, a.m + b.m};
            });
        const OpenBoundaryState& st = ob.state();
        out.insert(out.end(), {st.volume_in, st.volume_out, inside.v, ob.prescribed_inflow_rate(world.time()),
                               st.mass_in, st.mass_out, inside.m});
        // Per boundary: the flow through it, positive in its own direction (into the domain at an inflow,
        // out of it at an outflow), averaged over the steps since the last output time
        // (sim/boundary/open_boundary.hpp), and the pressure it imposes now.
        for (std::size_t b = 0; b < ob.flows().size(); ++b)
          out.insert(out.end(), {ob.mean_flow(b, world.time()), ob.flows()[b].pressure});
        break;
      }
      case ProbeType::OrificeArea: {
        // Open area of the valve projected on the disc (sim/physiology/orifice.hpp), the valve's particles in
        // array order (the raster does not depend on the order).
        const std::vector<char> in_set = body_mask(world, pr.bodies);
        std::vector<Vec3> pts;
        for (std::size_t i = 0; i < n; ++i)
          if (in_set[P.body[i]]) pts.push_back(P.x[i]);
        out.push_back(orifice_area(pts, world.scene().spacing, pr.point, pr.normal, pr.radius));
        break;
      }
      case ProbeType::Stress: {
        // Largest and mean von Mises stress (eqs. 16-17, sim/solid/solid_tlsph.hpp) over the bodies'
        // particles.
        const std::vector<char> in_set = body_mask(world, pr.bodies);
        const Solids& S = world.solids();
        struct MS {
          double max = 0, sum = 0, count = 0;
        };
        const MS r = parallel_reduce(
            S.size(), MS{},
            [&](std::size_t s) {
              if (!in_set[P.body[S.at(s)]]) return MS{};
              const double vm = S.von_mises(s);
              return MS{vm, vm, 1.0};
            },
            [](const MS& a, const MS& b) {
              return MS{std::max(a.max, b.max), a.sum + b.sum, a.count + b.count};
            });
        // Shells: the largest von Mises stress over a particle's Gauss points (sim/solid/shell.hpp).
        const Shells& Sh = world.shells();
        const MS rs = parallel_reduce(
            Sh.size(), MS{},
            [&](std::size_t s) {
              if (!in_set[P.body[Sh.at(s)]]) return MS{};
              const double vm = Sh.von_mises(s);
              return MS{vm, vm, 1.0};
            },
            [](const MS& a, const MS& b) {
              return MS{std::max(a.max, b.max), a.sum + b.sum, a.count + b.count};
            });
        const MS all{std::max(r.max, rs.max), r.sum + rs.sum, r.count + rs.count};
        // The 95th percentile (nearest rank) of the gathered values and the largest principal Green-Lagrange
        // strain (eq. 15; for shells the in-plane strain at the Gauss points through the thickness,
        // Shells::strain): gathered in array order, so the same for any thread count.
        std::vector<double> vm;
        double strain = 0.0;
        for (std::size_t s = 0; s < S.size(); ++s)
          if (in_set[P.body[S.at(s)]]) {
            vm.push_back(S.von_mises(s));
            strain = std::max(strain, largest_principal_strain(S.F(s)));
          }
        for (std::size_t s = 0; s < Sh.size(); ++s)
          if (in_set[P.body[Sh.at(s)]]) {
            vm.push_back(Sh.von_mises(s));
            strain = std::max(strain, Sh.strain(s));
          }
        out.insert(out.end(), {all.max, all.count > 0 ? all.sum / all.count : 0.0,
                               percentile_nearest_rank(vm, 95.0), strain});
        if (pr.per_body) {
          // Per body, in array order (solids, then shells): the largest value (the first particle on ties),
          // the nearest-rank 95th percentile, and where the peak particle sits on its cusp at t = 0: its
          // height above the annulus plane (point, normal) and its fraction s of the cusp's angular span
          // (0 and 1 the cusp's ends at the commissures, 0.5 its middle).
          Vec3 u, v;
          plane_frame(pr.normal, u, v);
          const Vec3 axis = pr.normal.normalized();
          for (std::size_t b = 0; b < pr.bodies.size(); ++b) {
            std::vector<double> vals;
            double best = -1.0;
            Vec3 where = Vec3::Constant(kNaN);
            auto visit = [&](std::size_t particle, double value) {
              if (P.body[particle] != pr.bodies[b]) return;
              vals.push_back(value);
              if (value > best) {
                best = value;
                where = P.x0[particle];
              }
            };
            for (std::size_t s = 0; s < S.size(); ++s) visit(S.at(s), S.von_mises(s));
            for (std::size_t s = 0; s < Sh.size(); ++s) visit(Sh.at(s), Sh.von_mises(s));
            const CuspFrame& f = cusp_frames_[k][b];
            double height = kNaN, frac = kNaN;
            if (!vals.empty()) {
              height = (where - pr.point).dot(axis);
              const double phi =
                  wrap_angle(std::atan2((where - pr.point).dot(v), (where - pr.point).dot(u)) - f.theta_c);
              frac = f.phi_max > f.phi_min ? (phi - f.phi_min) / (f.phi_max - f.phi_min) : 0.5;
            }
            out.insert(out.end(), {vals.empty() ? kNaN : best,
                                   vals.empty() ? kNaN : percentile_nearest_rank(vals, 95.0), height, frac});
          }
        }
        break;
      }
      case ProbeType::MaxSpeed: {
        // Largest speed of a fluid particle (buffers excluded) of the listed bodies (all fluid when none)
        // inside the region (everywhere when none).
        const std::vector<char> in_set = body_mask(world, pr.bodies);
        auto counted = [&](std::size_t i) {
          return P.kind[i] == Kind::Fluid && (pr.bodies.empty() || in_set[P.body[i]]);
        };
        if (pr.smoothed) {
          // The speed of the kernel-averaged velocity at each such particle, Shepard-normalised (eq. 4
          // divided by sum_j V_j W_ij, V_j = m_j / rho_j, over the counted particles within the kernel's
          // support): the continuum velocity the particles carry, without their particle-scale noise (a
          // single fast particle, 5.3 m/s in a 2.3 m/s jet at stop 56, counts for its share of the average).
          const CubicSpline& K = world.kernel();
          const double R = K.support;
          std::optional<Box> grown;
          if (pr.region) grown = Box{pr.region->min - Vec3::Constant(R), pr.region->max + Vec3::Constant(R)};
          std::vector<std::size_t> near;
          std::vector<Vec3> pts;
          for (std::size_t i = 0; i < n; ++i)
            if (counted(i) && (!grown || grown->contains(P.x[i]))) near.push_back(i), pts.push_back(P.x[i]);
          const PointGrid grid(std::move(pts), R);
          const double best = parallel_reduce(
              near.size(), -1.0,
              [&](std::size_t a) {
                const std::size_t i = near[a];
                if (pr.region && !pr.region->contains(P.x[i])) return -1.0;
                Vec3 vw = Vec3::Zero();
                double w = 0.0;
                grid.for_each_within(P.x[i], R, [&](std::size_t b) {
                  const std::size_t j = near[b];
                  const double Wj = K.W((P.x[j] - P.x[i]).norm()) * P.m[j] / P.rho[j];
                  vw += Wj * P.v[j];
                  w += Wj;
                });
                return w > 0.0 ? (vw / w).norm() : P.v[i].norm();
              },
              [](double a, double b) { return std::max(a, b); });
          out.push_back(best >= 0.0 ? best : kNaN);
          break;
        }
        const double best = parallel_reduce(
            n, -1.0,
            [&](std::size_t i) {
              if (!counted(i) || (pr.region && !pr.region->contains(P.x[i]))) return -1.0;
              return P.v[i].norm();
            },
            [](double a, double b) { return std::max(a, b); });
        out.push_back(best >= 0.0 ? best : kNaN);
        break;
      }
      case ProbeType::Coaptation: {
        const CoaptationStats c = coaptation(world, pr);
        for (std::size_t k = 0; k < c.height.size(); ++k) out.insert(out.end(), {c.height[k], c.length[k]});
        out.insert(out.end(), {c.central_height, c.effective_height});
        if (pr.per_body)
          out.insert(out.end(), c.effective_per_leaflet.begin(), c.effective_per_leaflet.end());
        break;
      }
      case ProbeType::Displacement: {
        std::size_t at = n;
        for (std::size_t i = 0; i < n && at == n; ++i)
          if (P.id[i] == tracked_id_[k]) at = i;
        const Vec3 u = at == n ? Vec3::Constant(kNaN) : Vec3(P.x[at] - P.x0[at]);
        for (int d = 0; d < 3; ++d) out.push_back(u[d]);
        break;
      }
      case ProbeType::GapArea: {
        // The orifice_area raster split into central and commissural parts (sim/physiology/orifice.hpp).
        const std::vector<char> in_set = body_mask(world, pr.bodies);
        std::vector<Vec3> pts;
        for (std::size_t i = 0; i < n; ++i)
          if (in_set[P.body[i]]) pts.push_back(P.x[i]);
        const OrificeRegions r = orifice_regions(pts, world.scene().spacing, pr.point, pr.normal, pr.radius,
                                                 pr.central_radius, pr.commissures);
        double comm = 0.0;
        for (double a : r.commissural) comm += a;
        out.insert(out.end(), {r.total, r.central, comm});
        out.insert(out.end(), r.commissural.begin(), r.commissural.end());
        break;
      }
      case ProbeType::WallDistance: {
        // Smallest distance from a leaflet particle (those farther than `exclude` from the walls at t = 0)
        // to a wall particle, now; capped at `reach`. Minima: independent of the visiting order.
        const std::vector<char> walls = body_mask(world, pr.walls);
        const PointGrid grid(positions_of(P, walls, false), pr.reach);
        std::vector<int> slot(world.bodies().size(), -1);
        for (std::size_t b = 0; b < pr.bodies.size(); ++b) slot[pr.bodies[b]] = static_cast<int>(b);
        std::vector<double> per(pr.bodies.size(), kNaN);
        double all = kNaN;
        const std::vector<uint32_t>& ok = eligible_[k];
        for (std::size_t i = 0; i < n; ++i) {
          const int b = slot[P.body[i]];
          if (b < 0 || is_buffer(P.kind[i]) || !std::binary_search(ok.begin(), ok.end(), P.id[i])) continue;
          const double d = grid.nearest(P.x[i], pr.reach);
          per[b] = std::isnan(per[b]) ? d : std::min(per[b], d);
          all = std::isnan(all) ? d : std::min(all, d);
        }
        out.push_back(all);
        out.insert(out.end(), per.begin(), per.end());
        break;
      }
      case ProbeType::Gap: {
        const GapStats g = body_gap(world, pr.bodies);
        out.insert(out.end(), {g.min, static_cast<double>(g.overlaps)});
        break;
      }
    }
  }
  return out;
}

}  // namespace aortasph
