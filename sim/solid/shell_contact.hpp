// Contact of thin shells (docs/model.md, "Shell contact"): sheet against sheet (leaflets of separate bodies
// coapting, or two parts of one sheet that were not neighbours in the reference) and sheet against a wall or
// an elastic body (a leaflet touching the root wall).
//
// The idea follows the contact of SPHinXsys (Wu, Zhang & Hu; reference sheet /work/shared/reference/shell.md
// sect. 3): a repulsive contact pressure p = K f(gap) with a kernel-weighted patch, an offset so that bodies
// at the contact distance do not repel, self-contact only between particles farther apart than the cut-off
// in the reference configuration, and an impedance-like damper. What is our own:
//   - the gap is the distance to the partner's TANGENT PLANE, not centre to centre: for particle a and a
//     shell particle b of normal n_b, s = (x_a - x_b) . n_b, and the pair acts with the weight
//     A_a A_b W2(rho), W2 the 2-D cubic spline of smoothing length dx (support 2 dx) of the in-plane offset
//     rho = |(x_a - x_b) - s n_b|. The weights of a flat lattice of spacing dx sum to one per area
//     (sum_b A_b W2 = 1), so a sheet pressed on a sheet feels p A_a, and since every point of a sheet is
//     within dx / sqrt(2) of one of its particles, there is no hole between particles to slip through
//     (the sheets are thinner than dx; a centre-to-centre contact would let them pass between particles);
//   - a pair of two shell particles acts through both planes (a on b's plane, b on a's plane), shared in
//     proportion to the squares of the two gaps (half each for parallel sheets; edge on, the edge
//     particle's own plane, which holds the partner at a gap near 0 and says nothing about the contact,
//     gets no share), so the pair force is symmetric in the two; a shell particle and a wall or elastic
//     particle act through the shell's plane only (volumetric particles have no normal), except near an
//     edge, where the edge particle's patch is a disc of radius dx / 2 and a partner beyond its rim is
//     pushed from the rim (edge on: in the plane), the pair's weight rising from 0 at the patches' reach
//     dx / sqrt(2) (stop 60);
//   - a barrier law, p = K (d_c / s - 1) for 0 < s < d_c (d_c the contact distance), which grows without
//     bound as the gap closes: no load can press two sheets through each other, and at a pressure p the
//     gap is s = d_c K / (K + p) (K = 100 p gives d_c within 1 %). Its stiffness per area K d_c / s^2 sets
//     the step of the contacting particles (stable_dt);
//   - the damper acts on the normal gap rate, p_d = -c ds/dt with c = 2 zeta sqrt(k mu) per area (k the
//     stiffness per area at the present gap, mu the reduced mass per area), and the total never pulls;
//   - frictionless (no tangential force).
// Contact distance: d_c = t_a / 2 + t_b / 2 + margin for two sheets (t the thickness); a wall or elastic
// particle stands for a volume of half a spacing about its centre, so it counts dx / 2 in place of t / 2.
// The margin defaults to half the mean thickness of the shells of the pair (d_c = 1.5 t for two sheets).
//
// Every pair force is computed in one order (the lower particle id first) and the other particle takes its
// exact negative, so action = reaction bit for bit; the loops gather (each particle sums its own row), so
// the result does not depend on the thread count.
#pragma once

#include <vector>

#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "core/periodic.hpp"
#include "solid/shell.hpp"

namespace aortasph {

struct ShellContactParams {
  double stiffness = 0.0;  // K [Pa]; 0: off
  double margin = -1.0;    // [m]; < 0: half the mean thickness of the pair's shells
  double damping = 0.5;    // zeta, fraction of the critical damping of the contact spring
  double dx = 0.0;         // particle spacing [m] (the patch kernel's smoothing length, walls' half size)
};

class ShellContact {
 public:
  ShellContact() = default;
  // cutoff: the reference-neighbour radius of the shells (pairs of one body closer than this in the
  // reference never contact).
  ShellContact(const ShellContactParams& p, double cutoff) : p_(p), cutoff_(cutoff) {}
  bool active() const { return p_.stiffness > 0.0; }
  const ShellContactParams& params() const { return p_; }

  // Adds the contact forces to f (indexed like P) on every shell and elastic particle. shell_v: the shells'
  // velocities by slot (their sub-step velocities, World::step_shells), or null: P.v.
  void add_forces(const Particles& P, const NeighborSearch& nb, const Shells& sh, const Periodic& per,
                  std::vector<Vec3>& f, const std::vector<Vec3>* shell_v = nullptr) const;
  // The contact in sub-steps (World::step_shells): gather() lists, once per step from the neighbour lists,
  // each free shell particle's candidate partners (as add_forces would visit them); add_listed_forces()
  // then adds the contact forces on those particles at the current positions and directors and the
  // velocities shell_v (by slot), visiting only the listed pairs. Held particles (clamped, pinned) get no
  // row: they do not move. The pairs are those the lists hold within 3 dx at the gather; in a step a sheet
  // moves by at most cfl h |v| / (c0 + |v|) (the fluid's CFL counts its speed: 0.03 dx at 2 m/s in the
  // physio scene), and a pair acts within 2.4 dx.
  void gather(const Particles& P, const NeighborSearch& nb, const Shells& sh, const Periodic& per);
  void add_listed_forces(const Particles& P, const Shells& sh, const Periodic& per, std::vector<Vec3>& f,
                         const std::vector<Vec3>* shell_v) const;

  // Largest stable step of the contacting shell particles (those within twice the contact distance of a
  // partner): cfl sqrt(2 m / k) for the contact spring of stiffness k (both sides moving), cfl 2 m / c for
  // the damper, and a quarter of the gap over its closing speed. Infinity when no particle is near contact.
  double stable_dt(const Particles& P, const NeighborSearch& nb, const Shells& sh, const Periodic& per,
                   double cfl, const std::vector<Vec3>* shell_v = nullptr) const;

  // Diagnostics: the smallest gap s between a shell particle and a partner's plane within a patch, over
  // the pairs the lists hold (infinity if none).
  double min_gap(const Particles& P, const NeighborSearch& nb, const Shells& sh, const Periodic& per) const;

 private:
  struct Pair {
    Vec3 f_a = Vec3::Zero();  // force on a
    double k = 0.0, c = 0.0;  // spring stiffness [N/m] and damper [N s/m] of the pair, near contact
    double dt_close = 0.0;    // gap / closing speed of an approaching pair near contact (0: none)
    double gap = 0.0;         // smallest plane gap of the pair within a patch (infinity: none)
    bool near = false;
  };
  // vab = v_a - v_b.
  Pair pair(const Particles& P, const Shells& sh, std::size_t a, std::size_t b, const Vec3& xab,
            const Vec3& vab) const;
  bool candidate(const Particles& P, const Shells& sh, std::size_t i, std::size_t j) const;
  // The pair (i, j), x_ij = x_i - x_j, evaluated in one order for every pair (the lower id first) with the
  // velocities shell_v (by slot) for shells, or P.v; sign +1 when the force is on i, -1 when on j.
  struct Oriented {
    Pair pair;
    double sign;
  };
  Oriented oriented(const Particles& P, const Shells& sh, const Periodic& per, std::size_t i, std::size_t j,
                    const Vec3& xij, const std::vector<Vec3>* shell_v) const;
  template <class Visit>
  void visit_row(const Particles& P, const NeighborSearch& nb, const Shells& sh, const Periodic& per,
                 std::size_t i, const std::vector<Vec3>* shell_v, Visit&& visit) const;

  ShellContactParams p_;
  double cutoff_ = 0.0;
  std::vector<uint32_t> listed_row_, listed_offset_, listed_;  // gather(): rows (particle), CSR of partners
};

}  // namespace aortasph
