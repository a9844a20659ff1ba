// Fluid on both sides of a one-layer shell (issue 16 item 3; docs/model.md, "Fluid on both sides of a
// shell"). What the fluid's pair sums see of a shell is in fluid/shell_wall.hpp (imaginary wall particles on
// the side away from each fluid particle). This file keeps the two sides apart:
//
//  1. Side labels. Every particle whose neighbour list holds shell particles (fluid, walls, other bodies,
//     and shell particles with respect to OTHER shell bodies) gets, per shell body B near it, a label: the
//     nearest particle s of B and the side sigma = sign(n_s . (x - x_s)) (a fluid particle: n_s the
//     mid-surface normal, and within kGuardReach dx of that plane the side of the sheet's surface,
//     closest_on_sheet, as the guard below, beyond the sheet's outline too); the label is "at an edge" when
//     s lies in the two or three rows along an edge of the sheet (free or supported).
//  2. Masking. A pair (a, b) with a fluid particle in it is taken out of both neighbour lists for this step
//     when it straddles a sheet: some body B labels a and b on opposite sides and, when both labels are
//     interior, that is enough; near an edge the segment x_a -> x_b must also pierce B's sheet, i.e. cross
//     the tangent plane of one of B's particles within 0.8 dx of it and, for a particle near an edge, no
//     more than dx / 2 outward of it (a patch test, so that fluid passes round a free edge but not through
//     the sheet next to it). A pair of a fluid particle and a shell
//     particle of B is masked by the other bodies only (its own sheet is what its imaginary particles
//     stand for). Shell-shell and solid-solid pairs are never masked (contact needs them). This is the
//     "side masking" of /work/shared/reference/shell.md section 4, which SPHinXsys's one-sided coupling
//     lacks. The masked pairs move to the tail of their rows (NeighborSearch::set_end): every loop of the
//     step skips them, and the rows are restored from the lists' build before each step, so the masks do
//     not depend on their own history (checkpoints restart bitwise). A fluid material with `mask_density`
//     has its density follow the summation density across each step's changes of the masks
//     (boundary/mask_density.hpp, which keeps the last step's masks and saves them in checkpoints).
//  3. Guard. After the drift, a fluid particle near a sheet is checked against the sheet as a surface: the
//     triangles through its particles (solid/shell_mesh.hpp) at their current positions, with a skirt dx / 2
//     wide along every edge (where the sheet's patches end). The closest point c of that surface near the
//     label's particle and the normal n there (the mid-surface normals interpolated) give its side,
//     sign(n . (x - c)). A particle on the wrong side has crossed the sheet: it is put back on its side,
//     0.1 dx off the surface along n, its velocity relative to the sheet along n removed, and counted
//     (crossings()). A particle whose closest point is on the skirt's outer edge is beyond the sheet: it
//     may pass round an edge. A crossing made in the step is no deeper than the step's motion: where the
//     surface puts a particle on the wrong side deeper than its own displacement plus the sheet's (dt |v| of
//     the label's particle) plus dx / 50, the particle did not cross in this step; the label and the surface
//     disagree (beside an edge two surface elements can lie at nearly the same distance with different
//     normals, and the signed distance, the normal component of x - c, flips between them). Such a particle
//     is left where it is, not teleported through the sheet, and counted apart (label_disagreements()); the
//     next step labels it from the surface. (Until stop 37 the side was that of the nearest particle's
//     tangent plane, which a curved sheet leaves by d^2 / 2R at a distance d from the particle: in the
//     physiological valve it put back particles that were on their own side of the sheet.)
//
// Only the rows of particles near a shell are touched (the "band", found at each list build): the cost is
// proportional to the sheet's area, not to the fluid's volume.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "core/periodic.hpp"
#include "fluid/shell_wall.hpp"
#include "solid/shell.hpp"

namespace aortasph {

class ShellCoupling {
 public:
  ShellCoupling() = default;
  // Edge particles of every shell body from the reference configuration; rho_ref: the walls' reference
  // density (the imaginary particles' mass), support: the fluid kernel's.
  // triangles: the sheets' triangles by shell slot (ShellSheets), for the guard.
  ShellCoupling(const Particles& P, const Shells& shells,
                const std::vector<std::array<uint32_t, 3>>& triangles, double dx, double support,
                double rho_ref);

  bool active() const { return active_; }
  // After each list build: the band rows and a copy of their pairs as built.
  void on_build(const Particles& P, NeighborSearch& nb);
  // Particles appended since (World::append_to_lists: open-boundary buffers, far from any sheet): outside
  // the band. n: the new particle count.
  void on_append(std::size_t n) {
    if (active_) band_of_.resize(n, -1);
  }
  // Before the fluid sums of a step: the imaginary particles' normals and masses, the side labels and the
  // masks.
  void prepare(const Particles& P, const Shells& shells, NeighborSearch& nb, const Periodic& per);
  // After the drift of a step dt: fluid particles that crossed a sheet are put back (see above). Returns how
  // many.
  std::size_t guard(Particles& P, const Shells& shells, const Periodic& per, double dt);
  // The barrier (docs/model.md, "Fluid on both sides of a shell"): a fluid particle whose centre comes
  // within d_c = dx / 4 of a sheet's mid-surface (half its resting distance from a wall), on its own side and
  // over the sheet, is pushed back by a contact pressure p = K (1 - s / d_c) - c ds/dt (never pulling; s the
  // gap to the sheet's surface, the guard's (closest_on_sheet), along its normal there; weighted over the
  // shell particles round the closest point like the shell contact, sim/solid/shell_contact.hpp), and the
  // shell particles take the opposite force. (Until stop 37 s was the gap to each shell particle's tangent
  // plane, which on a curved sheet misses a particle near it.) K per fluid material [Pa]
  // (0: off). It is stiff for a light sheet (a 0.45 mm leaflet has half the mass per area of one fluid
  // particle), so it is evaluated in the shells' sub-steps (World::step_shells), not held over the fluid's
  // step: barrier_begin() once per step after prepare() (the labels) picks the pairs that can come within
  // reach during the step (the shells move by at most `margin`), barrier_substep() gives the shell particles'
  // forces at their current positions, directors and velocities (by slot) and adds h times the opposite
  // force to the fluid particles' impulses, and barrier_end() adds the fluid's mean force over the step,
  // impulse / (dt m), to P.a: the impulses are equal and opposite, bit for bit.
  void barrier_begin(const Particles& P, const Shells& shells, const Periodic& per,
                     const std::vector<double>& K, double margin);
  void barrier_substep(const Particles& P, const Shells& shells, const Periodic& per,
                       const std::vector<double>& K, const std::vector<Vec3>& shell_v, double h,
                       std::vector<Vec3>& shell_force);
  void barrier_end(Particles& P, double dt) const;

  const ShellWall& wall() const { return wall_; }
  // Whether particle i's row can hold masks: a shell particle in its full row at the last list build.
  bool in_band(std::size_t i) const { return i < band_of_.size() && band_of_[i] >= 0; }

  // The side (+1 / -1) on which the last prepare() labelled particle i with respect to shell body `body`
  // (0: no label).
  int side(uint32_t i, uint16_t body) const {
    if (i >= band_of_.size() || band_of_[i] < 0) return 0;
    const Labels& L = labels_[static_cast<std::size_t>(band_of_[i])];
    for (uint8_t q = 0; q < L.n; ++q)
      if (L.l[q].body == body) return L.l[q].side;
    return 0;
  }
  long crossings() const { return crossings_; }
  void set_crossings(long c) { crossings_ = c; }
  // The put-backs of the last guard() call, in band order (deterministic): which fluid particle, where it
  // was found (over the sheet), the shell body, how far over [m] and whether the sheet's triangles (true) or
  // the nearest particle's tangent plane (false: beyond the sheet's outline, in a hole of it) decided.
  struct PutBack {
    uint32_t id = 0;
    Vec3 x = Vec3::Zero();
    uint16_t body = 0;
    double depth = 0.0;
    bool sheet = false;
  };
  const std::vector<PutBack>& last_put_backs() const { return put_backs_; }
  // Particles the guard found on the wrong side deeper than the step could have taken them (see above).
  long label_disagreements() const { return disagreements_; }
  void set_label_disagreements(long c) { disagreements_ = c; }
  std::size_t masked_pairs() const { return masked_; }
  std::size_t rim_particles() const {
    std::size_t c = 0;
    for (const uint8_t r : rim_) c += r;
    return c;
  }

 private:
  struct Label {
    uint32_t nearest = 0;  // particle index of the nearest particle of the body
    uint16_t body = 0;
    int8_t side = 0;  // +1 / -1
    uint8_t edge = 0;
  };
  static constexpr int kLabels = ShellWall::kSides;
  struct Labels {
    std::array<Label, kLabels> l;
    uint8_t n = 0;
  };

  // The guard's surface: the sheets' triangles and the skirt along their edges (two triangles per boundary
  // edge (i, j): i, j, j' and i, j', i', where i' = x_i + dx / 2 times i's outward direction). A vertex is a
  // slot, outward-shifted when its bit in `outer` is set; bit m of open_edge marks the edge opposite vertex m
  // as the surface's outline (the skirt's outer edge; a boundary edge without a skirt), bit m of open_vertex
  // vertex m as on the outline.
  // The guard checks, and the labels of fluid particles take, the surface's side within this many spacings of
  // the nearest particle's tangent plane (the surface leaves that plane by d^2 / 2R at a distance d from the
  // particle: 0.1-0.3 mm at d = 0.6-0.9 mm in the folds by the aortic commissures at dx = 1 mm; at a quarter
  // spacing, stop 37 saw labels from the plane and a guard from the surface disagree there).
  static constexpr double kGuardReach = 0.5;
  struct SheetTri {
    std::array<uint32_t, 3> slot{};
    uint8_t outer = 0, open_edge = 0, open_vertex = 0;
  };
  // The closest point of the guard's surface to fluid particle a, from the triangles round slot s (its
  // triangles and their neighbours'): found, on the outline, the signed distance along the interpolated
  // normal n, and n.
  struct Closest {
    bool found = false, outline = false;
    double sigma = 0.0;
    Vec3 n = Vec3::Zero();
    Vec3 c = Vec3::Zero();  // the closest point of the flat triangles, from the particle
  };
  void build_guard_surface(std::size_t n, const std::vector<std::array<uint32_t, 3>>& triangles);
  Closest closest_on_sheet(const Particles& P, const Shells& shells, const Periodic& per, uint32_t a,
                           std::size_t s) const;
  bool blocked(const Particles& P, const Periodic& per, uint32_t a, uint32_t b) const;
  // A fluid particle's gap to each sheet near it in a sub-step (one per label): the unit normal e towards
  // the particle's side and the gap along it (0: out of reach); the closest point is at -gap e from the
  // particle.
  struct Gap {
    uint16_t body = 0;
    double gap = 0.0;
    Vec3 e = Vec3::Zero();
  };
  // The barrier's force on fluid particle a (its gaps g) from shell particle q moving at vq (zero outside
  // the barrier).
  Vec3 barrier_pair(const Particles& P, const Shells& shells, const Periodic& per, uint32_t a,
                    const std::array<Gap, kLabels>& g, uint32_t q, const Vec3& vq, double K) const;
  bool pierces(const Particles& P, const Periodic& per, uint32_t a, uint32_t b, uint16_t body) const;
  // Whether the segment xa -> xb crosses the sheet of `body` near the shell particles of band row `row`.
  bool segment_pierces(const Particles& P, const Periodic& per, const Vec3& xa, const Vec3& xb, int32_t row,
                       uint16_t body) const;

  bool active_ = false;
  double dx_ = 0.0, patch2_ = 0.0;
  std::vector<uint8_t> edge_;  // by shell slot
  std::vector<uint8_t> rim_;   // by shell slot: the outermost row of an edge (ShellWall::cap)
  // Edge particles (slots), their reference neighbours (slots) with kernel weights (CSR), and by particle
  // index the current outward in-plane direction of an edge particle (zero elsewhere).
  std::vector<uint32_t> edge_slot_, edge_offset_, edge_nbr_;
  std::vector<double> edge_w_;
  std::vector<Vec3> edge_out_;
  std::vector<SheetTri> tris_;
  std::vector<uint32_t> tri_offset_, tri_of_;  // by slot: the triangles touching it (CSR)
  // By slot: the triangles touching it and those touching their vertices, each once, ascending (CSR): the
  // candidates of closest_on_sheet, fixed by the mesh.
  std::vector<uint32_t> near_offset_, near_of_;
  ShellWall wall_;
  // Band: rows holding a shell particle, their pairs as built (CSR) and their labels this step.
  std::vector<uint32_t> band_;    // particle indices
  std::vector<int32_t> band_of_;  // by particle: index into band_, or -1
  std::vector<uint32_t> saved_offset_, saved_;
  std::vector<Labels> labels_;
  std::vector<Vec3> x_before_;  // band rows' positions at prepare() (the guard's path near free edges)
  // The barrier's candidate pairs this step (barrier_begin): band rows that have any (index into band_),
  // their partners (CSR), and the fluid rows' impulses summed over the sub-steps.
  std::vector<uint32_t> bar_rows_, bar_offset_, bar_;
  std::vector<int32_t> bar_of_band_;  // by band row: index into bar_rows_, or -1
  std::vector<Vec3> bar_impulse_;
  std::vector<std::array<Gap, kLabels>> bar_gap_;  // by bar row (fluid rows): this sub-step's gaps
  long crossings_ = 0;
  long disagreements_ = 0;
  std::size_t masked_ = 0;
  std::vector<PutBack> put_back_scratch_;  // by band row, written where the guard moves the row
  std::vector<PutBack> put_backs_;
};

}  // namespace aortasph
