#include "solid/shell_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/kernel.hpp"
#include "core/parallel.hpp"

namespace aortasph {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool volumetric(Kind k) {
  return k == Kind::Wall || k == Kind::Elastic;
}

}  // namespace

bool ShellContact::candidate(const Particles& P, const Shells& sh, std::size_t i, std::size_t j) const {
  const Kind ki = P.kind[i], kj = P.kind[j];
  const bool si = ki == Kind::Shell, sj = kj == Kind::Shell;
  if (!si && !sj) return false;  // one shell at least
  if (!(si || volumetric(ki)) || !(sj || volumetric(kj))) return false;
  if (P.body[i] != P.body[j]) return true;
  if (!si || !sj) return false;
  // One sheet: only parts that were not neighbours in the reference (SPHinXsys ShellSelfContactRelation).
  const long a = sh.slot(i), b = sh.slot(j);
  if (a < 0 || b < 0) return false;
  return (sh.reference(static_cast<std::size_t>(a)) - sh.reference(static_cast<std::size_t>(b))).norm() >
         cutoff_;
}

// The pair (a, b), xab = x_a - x_b: force on a (b takes its negative), and the pair's stiffness, damper and
// closing time near contact.
ShellContact::Pair ShellContact::pair(const Particles& P, const Shells& sh, std::size_t a, std::size_t b,
                                      const Vec3& xab, const Vec3& vab) const {
  Pair out;
  out.gap = kInf;
  const double dx = p_.dx;
  const long sa = sh.slot(a), sb = sh.slot(b);
  const bool a_shell = sa >= 0, b_shell = sb >= 0;
  const auto slot = [](long s) { return static_cast<std::size_t>(s); };
  const double ta = a_shell ? sh.thickness(slot(sa)) : 0.0, tb = b_shell ? sh.thickness(slot(sb)) : 0.0;
  const double margin = p_.margin >= 0.0       ? p_.margin
                        : (a_shell && b_shell) ? 0.25 * (ta + tb)
                                               : 0.5 * (ta + tb);  // one of them is 0
  const double dc = (a_shell ? 0.5 * ta : 0.5 * dx) + (b_shell ? 0.5 * tb : 0.5 * dx) + margin;
  const double area_a = a_shell ? sh.area(slot(sa)) : dx * dx;
  const double area_b = b_shell ? sh.area(slot(sb)) : dx * dx;
  // Mass per area; a wall does not move (its share of the reduced mass is infinite).
  const auto mu = [&](std::size_t i, long s) {
    if (s >= 0) return sh.mass(slot(s)) / sh.area(slot(s));
    return P.kind[i] == Kind::Wall ? kInf : P.m[i] / (dx * dx);
  };
  const double mua = mu(a, sa), mub = mu(b, sb);
  const double mu_r = std::isinf(mua) ? mub : std::isinf(mub) ? mua : mua * mub / (mua + mub);
  // Two sheets: the two planes share the pair by the squares of their gaps, half each for parallel sheets.
  // Edge on (a free edge against a sheet's face) the partner sits in the edge particle's own plane (gap
  // near 0), where that plane says nothing about the contact: its share goes to zero.
  double share_b = 1.0, share_a = 1.0;  // of the term on b's plane, on a's plane
  if (a_shell && b_shell) {
    const double gb = xab.dot(sh.director(slot(sb))), ga = xab.dot(sh.director(slot(sa)));
    const double sum = ga * ga + gb * gb;
    share_b = sum > 0.0 ? gb * gb / sum : 0.5;
    share_a = sum > 0.0 ? ga * ga / sum : 0.5;
  }
  double weight = 1.0;
  const double K = p_.stiffness;
  // Particle o against the tangent plane of shell particle q (slot s); d = x_o - x_q, v = v_o - v_q.
  // Returns the force on o.
  const auto term = [&](long s, const Vec3& d, const Vec3& v) -> Vec3 {
    const Vec3& nq = sh.director(slot(s));
    const double snq = d.dot(nq);
    const double rho = std::sqrt(std::max(d.squaredNorm() - snq * snq, 0.0));  // the weight's distance
    if (rho >= 2.0 * dx) return Vec3::Zero();
    // Against a wall or elastic particle o, the sheet near o is the patch o faces (the one of q and its
    // neighbours nearest to o), not q's tangent plane, which is off the sheet by about rho^2 / 2R at rho on a
    // curved sheet. The gap is the larger of o's distance to the two planes, the direction that of the
    // patch: where q's plane passes through o away from the sheet (a commissure post 1.8 mm from a
    // leaflet's corner particle, the leaflet curving away from it), q's gap alone was ~0 and changed side
    // with each pass of a post particle, flipping a barrier of up to 1000 K, and the leaflet blew up at
    // peak ejection (aortic_valve_cycle_physio.json at 0.2043 s, docs/validation.md); the patch's gap alone
    // keeps pushing q while q moves off (8.9 ms into that scene: the patch, by the wall, did not move), and
    // q's plane, carried away with it, bounds that. Between two sheets q's own plane (their shares, above,
    // handle edge on).
    std::size_t ps = slot(s);
    Vec3 dp = d;
    if (!(a_shell && b_shell)) {
      const auto [t, off] = sh.nearest_patch(ps, d);
      ps = t;
      dp = d - off;
    }
    const Vec3& n = sh.director(ps);
    const double sn = dp.dot(n);
    double g = std::max(std::abs(sn), std::abs(snq));
    if (g >= 2.0 * dc) return Vec3::Zero();
    // A wall or elastic particle whose foot on the plane, x_o - s n, lies beyond an edge of the sheet (not
    // within dx / sqrt(2) of a particle of it: the patches of a lattice of spacing dx cover the sheet out to
    // dx / 2 beyond its edge rows) is not over the sheet: edge on, it sits near the plane of the particles
    // along the edge, whose gap says nothing about the contact (two sheets share such a pair by their gaps,
    // above). Without this, a wall particle in the plane of a free edge (a commissure post) set a barrier
    // stiffness without bound and a step of 1e-8 s.
    const Vec3 foot = dp - sn * n;  // o's foot on the plane, from the patch particle
    if (!(a_shell && b_shell) && !sh.over_sheet(ps, foot, std::sqrt(0.5) * dx)) return Vec3::Zero();
    // Near an edge a wall or elastic particle o meets the patch as a disc of radius dx / 2 (the edge
    // particle's own half spacing), not as its plane: beyond the disc's rim (foot more than dx / 2 from the
    // patch particle) the gap is the distance from the rim, and the force points from the rim to o, so a
    // wall reached edge on pushes the edge back in its plane. The pair's weight falls linearly to zero
    // between dx / 2 and the patches' reach dx / sqrt(2), so that it comes in continuously. Until stop 60 the
    // plane's gap (~0 edge on) set a barrier along the normal at once: 48 MPa on a lunula's top edge meeting
    // the root's wall at the sinotubular junction, 10 N on a particle of 0.45 mg, 105 m/s in one sub-step
    // (aortic_valve_cycle_physio.json with a lunula, stop 60).
    double ramp = 1.0;
    Vec3 e = sn >= 0.0 ? n : Vec3(-n);  // from the plane (q's or the patch's) towards o
    if (!(a_shell && b_shell) && sh.near_edge(ps)) {
      const double reach = std::sqrt(0.5) * dx, beyond = foot.norm() - 0.5 * dx;
      ramp = std::clamp((reach - 0.5 * dx - beyond) / (reach - 0.5 * dx), 0.0, 1.0);
      if (ramp <= 0.0) return Vec3::Zero();
      if (beyond > 0.0) {
        const Vec3 rim_to_o = sn * n + beyond * foot.normalized();
        g = std::max(rim_to_o.norm(), std::abs(snq));
        e = rim_to_o.normalized();
      }
    }
    const double w = ramp * weight * area_a * area_b * cubic_spline_2d(rho, dx);
    const double rate = v.dot(e);  // d(gap)/dt
    out.near = true;
    // The pair's gap and closing time are those of the plane that carries at least half of it (both for
    // parallel sheets): edge on, the edge particle's own plane holds the partner at a gap near 0 with a
    // share near 0, and its closing time (gap / speed, ~1e-6 s in the closing valve) would set the step for
    // nothing.
    // The closing time is taken on a gap of at least 0.1 d_c: closer, the barrier (9 K and more) and its
    // stiffness bound the step (k below); without the floor, a partner whose foot passes through the
    // tangent plane far out on the patch (a wall particle beside a curved leaflet) drove the step towards
    // zero as gap / speed (1e-9 s in the valve scene).
    if (weight >= 0.5) {
      out.gap = std::min(out.gap, g);
      if (rate < 0.0) {
        const double tc = std::max(g, 0.1 * dc) / -rate;
        out.dt_close = out.dt_close > 0.0 ? std::min(out.dt_close, tc) : tc;
      }
    }
    const double ge = std::max(g, 1e-3 * dc);
    const double ka = g < dc ? K * dc / (ge * ge) : K / dc;  // stiffness per area [Pa/m]
    const double ca = 2.0 * p_.damping * std::sqrt(ka * mu_r);
    out.k += ka * w;
    out.c += ca * w;
    if (g >= dc) return Vec3::Zero();
    const double p = std::max(K * (dc / ge - 1.0) - ca * rate, 0.0);  // barrier + damper, never pulling
    return (p * w) * e;
  };
  if (b_shell && share_b > 0.0) {  // a on b's plane
    weight = share_b;
    out.f_a += term(sb, xab, vab);
  }
  if (a_shell && share_a > 0.0) {  // b on a's plane
    weight = share_a;
    out.f_a -= term(sa, -xab, -vab);
  }
  return out;
}

ShellContact::Oriented ShellContact::oriented(const Particles& P, const Shells& sh, const Periodic& per,
                                              std::size_t i, std::size_t j, const Vec3& xij,
                                              const std::vector<Vec3>* shell_v) const {
  const auto velocity = [&](std::size_t q) -> const Vec3& {
    if (shell_v && P.kind[q] == Kind::Shell) return (*shell_v)[static_cast<std::size_t>(sh.slot(q))];
    return P.v[q];
  };
  // One order for every pair (the lower id first), so the two particles see exactly opposite forces.
  if (P.id[i] < P.id[j]) return {pair(P, sh, i, j, xij, Vec3(velocity(i) - velocity(j))), 1.0};
  const Vec3 xji = per.any ? per.image(P.x[j] - P.x[i]) : Vec3(P.x[j] - P.x[i]);
  return {pair(P, sh, j, i, xji, Vec3(velocity(j) - velocity(i))), -1.0};
}

template <class Visit>
void ShellContact::visit_row(const Particles& P, const NeighborSearch& nb, const Shells& sh,
                             const Periodic& per, std::size_t i, const std::vector<Vec3>* shell_v,
                             Visit&& visit) const {
  const auto& idx = nb.index();
  // The full row: the shell coupling may have cut masked fluid pairs off the end (NeighborSearch::end).
  for (uint32_t k = nb.begin(i); k < nb.full_end(i); ++k) {
    const uint32_t j = idx[k];
    if (!candidate(P, sh, i, j)) continue;
    const Vec3 xij = per.any ? per.image(P.x[i] - P.x[j]) : Vec3(P.x[i] - P.x[j]);
    if (xij.squaredNorm() >= 9.0 * p_.dx * p_.dx) continue;
    const Oriented o = oriented(P, sh, per, i, j, xij, shell_v);
    visit(o.pair, o.sign);
  }
}

void ShellContact::add_forces(const Particles& P, const NeighborSearch& nb, const Shells& sh,
                              const Periodic& per, std::vector<Vec3>& f,
                              const std::vector<Vec3>* shell_v) const {
  if (!active() || sh.empty() || nb.size() != P.size()) return;
  parallel_for_dynamic(P.size(), [&](std::size_t i) {
    if (P.kind[i] != Kind::Shell && P.kind[i] != Kind::Elastic) return;  // walls do not move
    Vec3 sum = Vec3::Zero();
    visit_row(P, nb, sh, per, i, shell_v, [&](const Pair& pr, double sign) {
      if (sign > 0.0)
        sum += pr.f_a;
      else
        sum -= pr.f_a;
    });
    f[i] += sum;
  });
}

void ShellContact::gather(const Particles& P, const NeighborSearch& nb, const Shells& sh,
                          const Periodic& per) {
  listed_row_.clear();
  listed_offset_.assign(1, 0);
  listed_.clear();
  if (!active() || sh.empty() || nb.size() != P.size()) return;
  for (std::size_t s = 0; s < sh.size(); ++s)
    if (sh.support(s) != 1 && sh.support(s) != 2) listed_row_.push_back(sh.at(s));
  std::vector<std::vector<uint32_t>> rows(listed_row_.size());
  const auto& idx = nb.index();
  parallel_for(listed_row_.size(), [&](std::size_t r) {
    const uint32_t i = listed_row_[r];
    for (uint32_t k = nb.begin(i); k < nb.full_end(i); ++k) {
      const uint32_t j = idx[k];
      if (!candidate(P, sh, i, j)) continue;
      const Vec3 xij = per.any ? per.image(P.x[i] - P.x[j]) : Vec3(P.x[i] - P.x[j]);
      if (xij.squaredNorm() < 9.0 * p_.dx * p_.dx) rows[r].push_back(j);
    }
  });
  for (const auto& row : rows) {
    listed_.insert(listed_.end(), row.begin(), row.end());
    listed_offset_.push_back(static_cast<uint32_t>(listed_.size()));
  }
}

void ShellContact::add_listed_forces(const Particles& P, const Shells& sh, const Periodic& per,
                                     std::vector<Vec3>& f, const std::vector<Vec3>* shell_v) const {
  parallel_for_dynamic(listed_row_.size(), [&](std::size_t r) {
    const uint32_t i = listed_row_[r];
    Vec3 sum = Vec3::Zero();
    for (uint32_t k = listed_offset_[r]; k < listed_offset_[r + 1]; ++k) {
      const uint32_t j = listed_[k];
      const Vec3 xij = per.any ? per.image(P.x[i] - P.x[j]) : Vec3(P.x[i] - P.x[j]);
      const Oriented o = oriented(P, sh, per, i, j, xij, shell_v);
      if (o.sign > 0.0)
        sum += o.pair.f_a;
      else
        sum -= o.pair.f_a;
    }
    f[i] += sum;
  });
}

double ShellContact::stable_dt(const Particles& P, const NeighborSearch& nb, const Shells& sh,
                               const Periodic& per, double cfl, const std::vector<Vec3>* shell_v) const {
  if (!active() || sh.empty() || nb.size() != P.size()) return kInf;
  return parallel_reduce(
      sh.size(), kInf,
      [&](std::size_t s) {
        if (sh.support(s) == 1 || sh.support(s) == 2) return kInf;  // held in place: no step to bound
        const std::size_t i = sh.at(s);
        double k = 0.0, c = 0.0, close = kInf;
        bool near = false;
        visit_row(P, nb, sh, per, i, shell_v, [&](const Pair& pr, double) {
          if (!pr.near) return;
          near = true;
          k += pr.k;
          c += pr.c;
          if (pr.dt_close > 0.0) close = std::min(close, pr.dt_close);
        });
        if (!near) return kInf;
        const double m = sh.mass(s);
        double dt = 0.25 * close;
        if (k > 0.0) dt = std::min(dt, cfl * std::sqrt(2.0 * m / k));
        if (c > 0.0) dt = std::min(dt, cfl * 2.0 * m / c);
        return dt;
      },
      [](double x, double y) { return std::min(x, y); });
}

double ShellContact::min_gap(const Particles& P, const NeighborSearch& nb, const Shells& sh,
                             const Periodic& per) const {
  if (sh.empty() || nb.size() != P.size()) return kInf;
  return parallel_reduce(
      sh.size(), kInf,
      [&](std::size_t s) {
        double g = kInf;
        visit_row(P, nb, sh, per, sh.at(s), nullptr,
                  [&](const Pair& pr, double) { g = std::min(g, pr.gap); });
        return g;
      },
      [](double x, double y) { return std::min(x, y); });
}

}  // namespace aortasph
