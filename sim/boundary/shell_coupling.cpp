#include "boundary/shell_coupling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "core/kernel.hpp"
#include "core/parallel.hpp"

namespace aortasph {

ShellCoupling::ShellCoupling(const Particles& P, const Shells& shells,
                             const std::vector<std::array<uint32_t, 3>>& triangles, double dx, double support,
                             double rho_ref)
    : active_(!shells.empty()), dx_(dx), patch2_(0.64 * dx * dx) {
  wall_.dx = dx;
  wall_.layers = static_cast<int>(std::floor(support / dx + 0.5));  // (k - 1/2) dx < support
  wall_.ghost_rho = rho_ref;
  // Edge particles: the first moment of the reference neighbourhood, sum_j W_ij (X_j - X_i) / sum_j W_ij,
  // vanishes inside a sheet and is about dx / 2 at its edge; over 0.1 dx flags the two or three rows along
  // every edge (only there is the exact patch test needed).
  const std::size_t n = shells.size();
  edge_.assign(n, 0);
  rim_.assign(n, 0);
  // The sheets' reference positions, then the wall particles (for the rim test below).
  std::vector<Vec3> X(n);
  for (std::size_t s = 0; s < n; ++s) X[s] = shells.reference(s);
  for (std::size_t i = 0; i < P.size(); ++i)
    if (P.kind[i] == Kind::Wall) X.push_back(P.x[i]);
  NeighborSearch nbs;
  nbs.build(X, support);
  const CubicSpline K(0.5 * support);
  parallel_for(n, [&](std::size_t s) {
    const uint16_t body = P.body[shells.at(s)];
    Vec3 moment = Vec3::Zero();
    double sum = 0.0;
    for (uint32_t k = nbs.begin(s); k < nbs.end(s); ++k) {
      const uint32_t t = nbs.index()[k];
      if (t >= n || P.body[shells.at(t)] != body) continue;
      const double w = K.W((X[t] - X[s]).norm());
      moment += w * (X[t] - X[s]);
      sum += w;
    }
    edge_[s] = sum <= 0.0 || moment.norm() > 0.1 * dx * sum;
    // The rim: the outermost row of an edge the fluid can pass round, i.e. edge particles with nothing
    // beyond them along the outward direction -moment: no particle of their sheet farther out than dx / 2,
    // and, for a particle held by a support, no wall particle within 1.5 dx and 45 degrees of it (an edge
    // fixed into a wall is not a rim; a free edge that runs up to a commissure post is)
    // (ShellWall::cap).
    if (!edge_[s] || moment.norm() <= 0.0) return;
    const Vec3 out = -moment.normalized();
    const bool held = shells.support(s) != 0;
    bool beyond = false;
    for (uint32_t k = nbs.begin(s); k < nbs.end(s) && !beyond; ++k) {
      const uint32_t t = nbs.index()[k];
      const Vec3 d = X[t] - X[s];
      beyond = t < n ? P.body[shells.at(t)] == body && d.dot(out) > 0.5 * dx
                     : held && d.squaredNorm() < 2.25 * dx * dx && d.dot(out) > 0.7 * d.norm();
    }
    rim_[s] = !beyond;
  });
  // Their reference neighbours and weights, for the current outward direction (prepare()).
  edge_offset_.assign(1, 0);
  for (std::size_t s = 0; s < n; ++s) {
    if (!edge_[s]) continue;
    const uint16_t body = P.body[shells.at(s)];
    for (uint32_t k = nbs.begin(s); k < nbs.end(s); ++k) {
      const uint32_t t = nbs.index()[k];
      if (t >= n || P.body[shells.at(t)] != body) continue;
      edge_nbr_.push_back(t);
      edge_w_.push_back(K.W((X[t] - X[s]).norm()));
    }
    edge_slot_.push_back(static_cast<uint32_t>(s));
    edge_offset_.push_back(static_cast<uint32_t>(edge_nbr_.size()));
  }
  build_guard_surface(n, triangles);
}

void ShellCoupling::build_guard_surface(std::size_t n,
                                        const std::vector<std::array<uint32_t, 3>>& triangles) {
  // Boundary edges: in one triangle only. Those between two edge particles get a skirt; any other is part of
  // the outline (a hole).
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& t : triangles)
    for (int m = 0; m < 3; ++m) ++uses[std::minmax(t[m], t[(m + 1) % 3])];
  const auto boundary = [&](uint32_t i, uint32_t j) { return uses.at(std::minmax(i, j)) == 1; };
  const auto skirted = [&](uint32_t i, uint32_t j) { return edge_[i] && edge_[j]; };
  std::vector<uint8_t> open_slot(n, 0);
  for (const auto& [e, c] : uses)
    if (c == 1 && !skirted(e.first, e.second)) open_slot[e.first] = open_slot[e.second] = 1;
  for (const auto& t : triangles) {
    SheetTri T;
    T.slot = t;
    for (int m = 0; m < 3; ++m) {
      const uint32_t i = t[(m + 1) % 3], j = t[(m + 2) % 3];  // the edge opposite vertex m
      if (boundary(i, j) && !skirted(i, j)) T.open_edge |= static_cast<uint8_t>(1u << m);
      if (open_slot[t[m]]) T.open_vertex |= static_cast<uint8_t>(1u << m);
      if (boundary(i, j) && skirted(i, j)) {
        // (i, j, j') and (i, j', i'): the outer edge j' i' is opposite vertex 0 of the second.
        tris_.push_back(SheetTri{{i, j, j}, 4, 0, 4});
        tris_.push_back(SheetTri{{i, j, i}, 6, 1, 6});
      }
    }
    tris_.push_back(T);
  }
  // Incidence by slot (CSR), in the triangles' order.
  const auto first = [](const SheetTri& T, int m) {  // the first vertex of T on its slot
    return (m < 1 || T.slot[m] != T.slot[0]) && (m < 2 || T.slot[m] != T.slot[1]);
  };
  tri_offset_.assign(n + 1, 0);
  for (const SheetTri& T : tris_)
    for (int m = 0; m < 3; ++m)
      if (first(T, m)) ++tri_offset_[T.slot[m] + 1];
  for (std::size_t s = 0; s < n; ++s) tri_offset_[s + 1] += tri_offset_[s];
  tri_of_.resize(tri_offset_[n]);
  std::vector<uint32_t> fill(tri_offset_.begin(), tri_offset_.end() - 1);
  for (std::size_t k = 0; k < tris_.size(); ++k)
    for (int m = 0; m < 3; ++m)
      if (first(tris_[k], m)) tri_of_[fill[tris_[k].slot[m]]++] = static_cast<uint32_t>(k);
  // Each slot's candidates for closest_on_sheet, once (they were gathered and sorted at every call: 2 % of
  // the physio scene's step, stop 43).
  near_offset_.assign(n + 1, 0);
  near_of_.clear();
  std::vector<uint32_t> near;
  for (std::size_t s = 0; s < n; ++s) {
    near.clear();
    for (uint32_t k = tri_offset_[s]; k < tri_offset_[s + 1]; ++k)
      for (const uint32_t v : tris_[tri_of_[k]].slot)
        near.insert(near.end(), tri_of_.begin() + tri_offset_[v], tri_of_.begin() + tri_offset_[v + 1]);
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    near_of_.insert(near_of_.end(), near.begin(), near.end());
    near_offset_[s + 1] = static_cast<uint32_t>(near_of_.size());
  }
}

void ShellCoupling::on_build(const Particles& P, NeighborSearch& nb) {
  if (!active_) return;
  nb.enable_row_ends();
  const std::size_t n = P.size();
  std::vector<uint8_t> in_band(n, 0);
  const auto& idx = nb.index();
  parallel_for(n, [&](std::size_t i) {
    if (P.kind[i] == Kind::Shell) {
      in_band[i] = 1;
      return;
    }
    for (uint32_t k = nb.begin(i); k < nb.full_end(i); ++k)
      if (P.kind[idx[k]] == Kind::Shell) {
        in_band[i] = 1;
        return;
      }
  });
  band_.clear();
  band_of_.assign(n, -1);
  saved_offset_.assign(1, 0);
  saved_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (!in_band[i]) continue;
    band_of_[i] = static_cast<int32_t>(band_.size());
    band_.push_back(static_cast<uint32_t>(i));
    saved_.insert(saved_.end(), idx.begin() + nb.begin(i), idx.begin() + nb.full_end(i));
    saved_offset_.push_back(static_cast<uint32_t>(saved_.size()));
  }
  labels_.assign(band_.size(), Labels{});
}

bool ShellCoupling::segment_pierces(const Particles& P, const Periodic& per, const Vec3& xa, const Vec3& xb,
                                    int32_t row, uint16_t body) const {
  if (row < 0) return false;
  const Vec3 ab = per.any ? per.image(xb - xa) : Vec3(xb - xa);
  for (uint32_t k = saved_offset_[row]; k < saved_offset_[row + 1]; ++k) {
    const uint32_t s = saved_[k];
    if (P.kind[s] != Kind::Shell || P.body[s] != body) continue;
    const Vec3& nrm = wall_.normal[s];
    const Vec3 as = per.any ? per.image(xa - P.x[s]) : Vec3(xa - P.x[s]);
    const double da = nrm.dot(as), db = nrm.dot(as + ab);
    if (da * db >= 0.0) continue;
    const Vec3 c = as + (da / (da - db)) * ab;  // where the segment meets s's tangent plane, from x_s
    // Near an edge the patch stops half a spacing outward of the particle (where the sheet ends).
    if (c.squaredNorm() < patch2_ && c.dot(edge_out_[s]) < 0.5 * dx_) return true;
  }
  return false;
}

bool ShellCoupling::pierces(const Particles& P, const Periodic& per, uint32_t a, uint32_t b,
                            uint16_t body) const {
  return segment_pierces(P, per, P.x[a], P.x[b], band_of_[a], body) ||
         segment_pierces(P, per, P.x[a], P.x[b], band_of_[b], body);
}

bool ShellCoupling::blocked(const Particles& P, const Periodic& per, uint32_t a, uint32_t b) const {
  const Kind ka = P.kind[a], kb = P.kind[b];
  if (!fluid_like(ka) && !fluid_like(kb)) return false;
  const int32_t ia = band_of_[a], ib = band_of_[b];
  if (ia < 0 || ib < 0) return false;
  const Labels& la = labels_[ia];
  const Labels& lb = labels_[ib];
  for (uint8_t p = 0; p < la.n; ++p) {
    const Label& A = la.l[p];
    if (kb == Kind::Shell && P.body[b] == A.body) continue;  // b's own sheet: its imaginary particles
    for (uint8_t q = 0; q < lb.n; ++q) {
      const Label& B = lb.l[q];
      if (B.body != A.body || B.side == A.side) continue;
      // Interior labels, or a wall (a wall particle is on one side of the sheet's plane, also where an edge
      // of the sheet is fixed to the wall: its pressure belongs to that side).
      if ((!A.edge && !B.edge) || ka == Kind::Wall || kb == Kind::Wall) return true;
      // The same order from either row, so that both rows of the pair decide alike.
      if (pierces(P, per, std::min(a, b), std::max(a, b), A.body)) return true;
    }
  }
  return false;
}

void ShellCoupling::prepare(const Particles& P, const Shells& shells, NeighborSearch& nb,
                            const Periodic& per) {
  if (!active_) return;
  const std::size_t n = P.size();
  wall_.normal.resize(n);
  wall_.ghost_mass.resize(n);
  parallel_for(shells.size(), [&](std::size_t s) {
    const uint32_t i = shells.at(s);
    wall_.normal[i] = shells.director(s);
    wall_.ghost_mass[i] = wall_.ghost_rho * shells.area(s) * dx_;
  });
  // Edge particles: the current outward direction in the tangent plane, minus the first moment of the
  // reference neighbours at their current positions.
  edge_out_.assign(n, Vec3::Zero());
  wall_.cap.assign(n, Vec3::Zero());
  parallel_for(edge_slot_.size(), [&](std::size_t e) {
    const uint32_t i = shells.at(edge_slot_[e]);
    Vec3 m = Vec3::Zero();
    for (uint32_t k = edge_offset_[e]; k < edge_offset_[e + 1]; ++k)
      m += edge_w_[k] * (P.x[shells.at(edge_nbr_[k])] - P.x[i]);
    const Vec3& nrm = wall_.normal[i];
    m -= m.dot(nrm) * nrm;
    const double len = m.norm();
    if (len > 0.0) edge_out_[i] = -m / len;
    if (rim_[edge_slot_[e]]) wall_.cap[i] = edge_out_[i];
  });
  // Rows as built, then the labels (also the imaginary particles' side for each fluid particle: outside the
  // band it has none).
  wall_.sides.assign(n, ShellWall::Sides{});
  uint32_t* rows = nb.row_data();
  x_before_.resize(band_.size());
  parallel_for(band_.size(), [&](std::size_t r) {
    const uint32_t i = band_[r];
    std::copy(saved_.begin() + saved_offset_[r], saved_.begin() + saved_offset_[r + 1], rows + nb.begin(i));
    nb.set_end(i, nb.full_end(i));
    Labels L;
    std::array<double, kLabels> best{};
    const bool shell_i = P.kind[i] == Kind::Shell;
    for (uint32_t k = saved_offset_[r]; k < saved_offset_[r + 1]; ++k) {
      const uint32_t j = saved_[k];
      if (P.kind[j] != Kind::Shell || (shell_i && P.body[j] == P.body[i])) continue;
      const Vec3 d = per.any ? per.image(P.x[i] - P.x[j]) : Vec3(P.x[i] - P.x[j]);
      const double d2 = d.squaredNorm();
      int slot = -1;
      for (int q = 0; q < L.n; ++q)
        if (L.l[q].body == P.body[j]) slot = q;
      if (slot < 0) {
        if (L.n == kLabels) continue;  // more shell bodies than labels around one particle: ignored
        slot = L.n++;
        best[slot] = d2 + 1.0;
        L.l[slot].body = P.body[j];
      }
      if (d2 < best[slot]) {
        best[slot] = d2;
        Label& l = L.l[slot];
        l.nearest = j;
        l.side = wall_.normal[j].dot(d) >= 0.0 ? 1 : -1;
        l.edge = edge_[static_cast<std::size_t>(shells.slot(j))];
      }
    }
    // A fluid particle close to a sheet takes the side of the sheet's surface (closest_on_sheet), the one the
    // guard checks: a tangent plane misjudges it on a curved sheet. Further off, the side of the plane of
    // the mid-surface's normal there (not the director's: a clamped director does not turn with its sheet).
    if (P.kind[i] == Kind::Fluid)
      for (uint8_t q = 0; q < L.n; ++q) {
        Label& l = L.l[q];
        const Vec3 d = per.any ? per.image(P.x[i] - P.x[l.nearest]) : Vec3(P.x[i] - P.x[l.nearest]);
        const std::size_t sl = static_cast<std::size_t>(shells.slot(l.nearest));
        const double sm = shells.normal(sl).dot(d);
        if (std::abs(sm) >= kGuardReach * dx_) {
          l.side = sm >= 0.0 ? 1 : -1;
          continue;
        }
        const Closest c = closest_on_sheet(P, shells, per, i, sl);
        // (Beyond the outline too: the side of the sheet's extension, which the guard judges once the
        // particle comes back over the sheet.)
        if (c.found && c.sigma != 0.0) l.side = c.sigma > 0.0 ? 1 : -1;
      }
    labels_[r] = L;
    x_before_[r] = P.x[i];
    ShellWall::Sides& S = wall_.sides[i];
    S.n = L.n;
    for (uint8_t q = 0; q < L.n; ++q) {
      S.body[q] = L.l[q].body;
      S.side[q] = L.l[q].side;
    }
  });
  // Masks: each row partitioned into kept pairs, local walls and masked pairs, each in their built order. A
  // fixed wall particle across a sheet from a fluid particle is a "local wall" for it (fluid/shell_wall.hpp:
  // its pressure extrapolated from the fluid particle alone, not the wall's own value, which belongs to the
  // other side), and the fluid particle is masked from the wall's row (so the wall's value is its own
  // side's). Without the local walls, a fluid particle in the corner of a sheet and the wall it is
  // attached to would lose the wall beyond the sheet's plane.
  wall_.local_begin.assign(n, ShellWall::kNoLocal);
  std::vector<uint32_t> masked(band_.size(), 0);
  parallel_for_dynamic(band_.size(), [&](std::size_t r) {
    const uint32_t a = band_[r];
    uint32_t* row = rows + nb.begin(a);
    const uint32_t len = nb.full_end(a) - nb.begin(a);
    const bool fluid_a = fluid_like(P.kind[a]);
    uint32_t kept = 0;
    thread_local std::vector<uint32_t> local, tail;
    local.clear();
    tail.clear();
    for (uint32_t k = 0; k < len; ++k) {
      const uint32_t b = row[k];
      if (!blocked(P, per, a, b))
        row[kept++] = b;
      else if (fluid_a && P.kind[b] == Kind::Wall)
        local.push_back(b);
      else
        tail.push_back(b);
    }
    if (fluid_a) wall_.local_begin[a] = nb.begin(a) + kept;
    std::copy(local.begin(), local.end(), row + kept);
    std::copy(tail.begin(), tail.end(), row + kept + local.size());
    nb.set_end(a, nb.begin(a) + kept + static_cast<uint32_t>(local.size()));
    masked[r] = static_cast<uint32_t>(tail.size());
  });
  masked_ = 0;
  for (const uint32_t m : masked) masked_ += m;
}

namespace {
// The thickness barrier's reach, in spacings (ShellCoupling::barrier).
constexpr double kBarrier = 0.25;
}  // namespace

Vec3 ShellCoupling::barrier_pair(const Particles& P, const Shells& shells, const Periodic& per, uint32_t a,
                                 const std::array<Gap, kLabels>& g, uint32_t q, const Vec3& vq,
                                 double K) const {
  const long sl = shells.slot(q);
  if (sl < 0 || K <= 0.0) return Vec3::Zero();
  const std::size_t s = static_cast<std::size_t>(sl);
  const Gap* G = nullptr;
  for (const Gap& x : g)
    if (x.body == P.body[q] && x.gap > 0.0) G = &x;
  if (G == nullptr) return Vec3::Zero();
  // The imaginary particles put the wall's surface at the mid-surface and fluid rests about dx / 2 off it
  // (a wall's first layer); the barrier sits inside that, whatever the sheet's own thickness.
  const double dc = kBarrier * dx_;
  // q's share: its area times the 2-D kernel at its distance from the closest point (a partition of unity
  // over the sheet, so the pressure acts on about dx^2 of it).
  const Vec3 qc = (per.any ? per.image(P.x[q] - P.x[a]) : Vec3(P.x[q] - P.x[a])) + G->gap * G->e;
  const double rho = qc.norm();
  if (rho >= 2.0 * dx_) return Vec3::Zero();
  const double w = dx_ * dx_ * shells.area(s) * cubic_spline_2d(rho, dx_);  // A_a A_q W2, A_a = dx^2
  const double rate = (P.v[a] - vq).dot(G->e);
  // Damper: half the critical damping of the spring K / d_c per area on the pair's reduced mass per area.
  const double mu_a = P.m[a] / (dx_ * dx_), mu_q = shells.mass(s) / shells.area(s);
  const double c = std::sqrt(K / dc * mu_a * mu_q / (mu_a + mu_q));
  const double p = std::max(K * (1.0 - G->gap / dc) - c * rate, 0.0);
  return (p * w) * G->e;
}

void ShellCoupling::barrier_begin(const Particles& P, const Shells& shells, const Periodic& per,
                                  const std::vector<double>& K, double margin) {
  bar_rows_.clear();
  bar_offset_.clear();
  bar_.clear();
  if (!active_) return;
  // A pair is a candidate when, with the sheet as it is at the start of the step, the fluid particle lies
  // within the barrier's reach widened by the margin (the same test from both ends, so the lists agree).
  const double dc = kBarrier * dx_;
  const auto candidate = [&](uint32_t a, uint32_t q) {
    if (K[P.material[a]] <= 0.0 || band_of_[a] < 0) return false;
    const long sl = shells.slot(q);
    if (sl < 0) return false;
    const Vec3& n = shells.director(static_cast<std::size_t>(sl));
    const Vec3 d = per.any ? per.image(P.x[a] - P.x[q]) : Vec3(P.x[a] - P.x[q]);
    const double sn = n.dot(d);
    // The surface may lie off q's tangent plane by up to (2 dx)^2 / 2R within the kernel's reach: half a
    // spacing for R = 4 dx.
    if (std::abs(sn) >= dc + 0.5 * dx_ + margin) return false;
    return (d - sn * n).squaredNorm() < (2.0 * dx_ + margin) * (2.0 * dx_ + margin);
  };
  const auto partner = [&](uint32_t i, uint32_t j) {
    const Kind ki = P.kind[i], kj = P.kind[j];
    if (ki == Kind::Fluid && kj == Kind::Shell) return candidate(i, j);
    if (ki == Kind::Shell && kj == Kind::Fluid) return candidate(j, i);
    return false;
  };
  const std::size_t nb = band_.size();
  std::vector<uint32_t> count(nb, 0);
  parallel_for(nb, [&](std::size_t r) {
    const uint32_t i = band_[r];
    if (P.kind[i] != Kind::Fluid && P.kind[i] != Kind::Shell) return;
    uint32_t c = 0;
    for (uint32_t k = saved_offset_[r]; k < saved_offset_[r + 1]; ++k) c += partner(i, saved_[k]) ? 1 : 0;
    count[r] = c;
  });
  bar_offset_.push_back(0);
  for (std::size_t r = 0; r < nb; ++r)
    if (count[r] > 0) {
      bar_rows_.push_back(static_cast<uint32_t>(r));
      bar_offset_.push_back(bar_offset_.back() + count[r]);
    }
  bar_.resize(bar_offset_.back());
  bar_impulse_.assign(bar_rows_.size(), Vec3::Zero());
  bar_gap_.assign(bar_rows_.size(), {});
  bar_of_band_.assign(nb, -1);
  for (std::size_t k = 0; k < bar_rows_.size(); ++k) bar_of_band_[bar_rows_[k]] = static_cast<int32_t>(k);
  parallel_for(bar_rows_.size(), [&](std::size_t k) {
    const std::size_t r = bar_rows_[k];
    const uint32_t i = band_[r];
    uint32_t out = bar_offset_[k];
    for (uint32_t m = saved_offset_[r]; m < saved_offset_[r + 1]; ++m)
      if (partner(i, saved_[m])) bar_[out++] = saved_[m];
  });
}

void ShellCoupling::barrier_substep(const Particles& P, const Shells& shells, const Periodic& per,
                                    const std::vector<double>& K, const std::vector<Vec3>& shell_v, double h,
                                    std::vector<Vec3>& shell_force) {
  shell_force.assign(shells.size(), Vec3::Zero());
  // The fluid rows' gaps to the sheets as they are now: over the sheet, on a label's side (across it, none:
  // the guard's business); beyond its outline, the distance to the outline, whose rim the barrier rounds
  // (fluid passes round a free edge, a quarter spacing off it). Without the rim, blood in the corner of a
  // leaflet's edge and a commissure post came round the rim within a step's motion (13 um) and in the same
  // step passed behind the sheet's skirt (aortic_valve_cycle_physio.json: the put-back at 10-20 ms,
  // docs/validation.md).
  const double dc = kBarrier * dx_;
  parallel_for(bar_rows_.size(), [&](std::size_t k) {
    const std::size_t r = bar_rows_[k];
    const uint32_t i = band_[r];
    std::array<Gap, kLabels>& g = bar_gap_[k];
    g = {};
    if (P.kind[i] != Kind::Fluid) return;
    const Labels& L = labels_[r];
    for (uint8_t q = 0; q < L.n; ++q) {
      const Label& l = L.l[q];
      const Closest c = closest_on_sheet(P, shells, per, i, static_cast<std::size_t>(shells.slot(l.nearest)));
      if (!c.found) continue;
      const double gap = c.outline ? c.c.norm() : l.side * c.sigma;
      if (gap <= 0.0 || gap >= dc) continue;
      g[q] = Gap{l.body, gap, c.outline ? Vec3(-c.c / gap) : Vec3(l.side * c.n)};
    }
  });
  // Gather: each row sums its own pairs (the fluid particle over its shell partners, the shell particle over
  // its fluid partners), each pair computed as barrier_pair(fluid, shell) from both ends, so action =
  // reaction bit for bit and the sums do not depend on the thread count.
  parallel_for(bar_rows_.size(), [&](std::size_t k) {
    const uint32_t i = band_[bar_rows_[k]];
    Vec3 sum = Vec3::Zero();
    if (P.kind[i] == Kind::Fluid) {
      for (uint32_t m = bar_offset_[k]; m < bar_offset_[k + 1]; ++m) {
        const uint32_t q = bar_[m];
        sum += barrier_pair(P, shells, per, i, bar_gap_[k], q,
                            shell_v[static_cast<std::size_t>(shells.slot(q))], K[P.material[i]]);
      }
      bar_impulse_[k] += h * sum;
    } else {
      const std::size_t s = static_cast<std::size_t>(shells.slot(i));
      for (uint32_t m = bar_offset_[k]; m < bar_offset_[k + 1]; ++m) {
        const uint32_t a = bar_[m];
        const int32_t ka = bar_of_band_[static_cast<std::size_t>(band_of_[a])];
        sum -= barrier_pair(P, shells, per, a, bar_gap_[static_cast<std::size_t>(ka)], i, shell_v[s],
                            K[P.material[a]]);
      }
      shell_force[s] = sum;
    }
  });
}

void ShellCoupling::barrier_end(Particles& P, double dt) const {
  parallel_for(bar_rows_.size(), [&](std::size_t k) {
    const uint32_t i = band_[bar_rows_[k]];
    if (P.kind[i] == Kind::Fluid) P.a[i] += bar_impulse_[k] / (dt * P.m[i]);
  });
}

namespace {

// The point of triangle (a, b, c) closest to the origin, as barycentric weights; a weight is exactly 0 when
// the point lies on the edge opposite its vertex (two zeros: on a vertex). Voronoi regions of the vertices,
// then the edges, then the face (Ericson, Real-Time Collision Detection, 2005, section 5.1.5).
std::array<double, 3> closest_to_origin(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0.0 && d2 <= 0.0) return {1.0, 0.0, 0.0};
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0.0 && d4 <= d3) return {0.0, 1.0, 0.0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return {1.0 - v, v, 0.0};
  }
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 0.0, 1.0};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return {1.0 - w, 0.0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0, 1.0 - w, w};
  }
  const double den = 1.0 / (va + vb + vc);
  const double v = vb * den, w = vc * den;
  return {1.0 - v - w, v, w};
}

}  // namespace

ShellCoupling::Closest ShellCoupling::closest_on_sheet(const Particles& P, const Shells& shells,
                                                       const Periodic& per, uint32_t a, std::size_t s) const {
  Closest out;
  if (tris_.empty()) return out;
  // The triangles touching s and those touching their vertices, each once, in ascending order.
  double best = std::numeric_limits<double>::infinity();
  for (uint32_t q = near_offset_[s]; q < near_offset_[s + 1]; ++q) {
    const uint32_t t = near_of_[q];
    const SheetTri& T = tris_[t];
    std::array<Vec3, 3> x, d;
    for (int m = 0; m < 3; ++m) {
      const uint32_t i = shells.at(T.slot[m]);
      x[m] = per.any ? per.image(P.x[i] - P.x[a]) : Vec3(P.x[i] - P.x[a]);  // from the fluid particle
      d[m] = shells.normal(T.slot[m]);  // the mid-surface's normal (a clamped director does not turn)
      if (T.outer & (1u << m)) {        // the edge's outward direction in that tangent plane
        const Vec3 o = edge_out_[i] - edge_out_[i].dot(d[m]) * d[m];
        const double len = o.norm();
        if (len > 0.0) x[m] += (0.5 * dx_ / len) * o;
      }
    }
    if ((x[1] - x[0]).cross(x[2] - x[0]).squaredNorm() <= 1e-12 * dx_ * dx_ * dx_ * dx_)
      continue;  // flat skirt
    const std::array<double, 3> w = closest_to_origin(x[0], x[1], x[2]);
    const Vec3 c = w[0] * x[0] + w[1] * x[1] + w[2] * x[2];
    const double d2 = c.squaredNorm();
    if (d2 >= best) continue;
    best = d2;
    const int zeros = (w[0] == 0.0) + (w[1] == 0.0) + (w[2] == 0.0);
    bool outline = false;
    for (int m = 0; m < 3; ++m) {
      if (zeros == 1 && w[m] == 0.0) outline = T.open_edge & (1u << m);
      if (zeros == 2 && w[m] != 0.0) outline = T.open_vertex & (1u << m);
    }
    const Vec3 n = (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]).normalized();
    // The flat triangle is a chord of the curved sheet (dx^2 / 8R off it mid-edge, as far as a tangent plane
    // half a spacing from its particle): the distance is taken to the Phong surface instead, the point c
    // moved by alpha sum_m w_m ((x_m - c) . d_m) d_m (Boubekeur & Alexa, "Phong tessellation", ACM TOG 27(5),
    // 2008), alpha = 1/2, which passes within O(dx^4 / R^3) of a circle through the particles.
    double lift = 0.0;
    for (int m = 0; m < 3; ++m) lift += w[m] * (x[m] - c).dot(d[m]) * n.dot(d[m]);
    out = Closest{true, outline, -n.dot(c) - 0.5 * lift, n, c};  // the particle is at -c from c
  }
  return out;
}

std::size_t ShellCoupling::guard(Particles& P, const Shells& shells, const Periodic& per, double dt) {
  put_backs_.clear();
  if (!active_) return 0;
  std::vector<uint8_t> moved(band_.size(), 0), disagree(band_.size(), 0);
  if (put_back_scratch_.size() < band_.size()) put_back_scratch_.resize(band_.size());
  const double reach = kGuardReach * dx_;
  parallel_for(band_.size(), [&](std::size_t r) {
    const uint32_t a = band_[r];
    if (P.kind[a] != Kind::Fluid) return;
    const Labels& L = labels_[r];
    for (uint8_t q = 0; q < L.n; ++q) {
      const Label& l = L.l[q];
      Vec3 nrm = wall_.normal[l.nearest];
      const Vec3 d = per.any ? per.image(P.x[a] - P.x[l.nearest]) : Vec3(P.x[a] - P.x[l.nearest]);
      double s = nrm.dot(d);
      bool by_sheet = false;
      const std::size_t sl = static_cast<std::size_t>(shells.slot(l.nearest));
      if (shells.normal(sl).dot(d) * l.side > reach) continue;
      const Closest c = closest_on_sheet(P, shells, per, a, sl);
      if (c.found && !c.outline) {
        // The side of the surface; a crossing of this step is no deeper than the step's motion.
        if (c.sigma * l.side > 0.0) continue;
        const Vec3 step = per.any ? per.image(P.x[a] - x_before_[r]) : Vec3(P.x[a] - x_before_[r]);
        if (-c.sigma * l.side > step.norm() + dt * P.v[l.nearest].norm() + 0.02 * dx_) {
          disagree[r] = 1;
          continue;
        }
        nrm = c.n;
        s = c.sigma;
        by_sheet = true;
      } else {
        // Beyond the outline: round an edge is allowed; in a hole of the sheet (an interior label), or with
        // no triangles, the tangent plane decides (near an edge: a path through its patches).
        if (s * l.side > 0.0 || (c.found && l.edge)) continue;
        if (l.edge && !segment_pierces(P, per, x_before_[r], P.x[a], static_cast<int32_t>(r), l.body))
          continue;
      }
      if (!moved[r]) put_back_scratch_[r] = PutBack{P.id[a], P.x[a], l.body, std::abs(s), by_sheet};
      P.x[a] += (l.side * 0.1 * dx_ - s) * nrm;
      if (per.any) per.wrap(P.x[a]);
      const double vr = (P.v[a] - P.v[l.nearest]).dot(nrm);
      if (vr * l.side < 0.0) P.v[a] -= vr * nrm;
      moved[r] = 1;
    }
  });
  std::size_t count = 0;
  for (std::size_t r = 0; r < moved.size(); ++r)
    if (moved[r]) {
      ++count;
      put_backs_.push_back(put_back_scratch_[r]);
    }
  crossings_ += static_cast<long>(count);
  for (const uint8_t m : disagree) disagreements_ += m;
  return count;
}

}  // namespace aortasph
