// Particle contact between bodies, paper eqs. (23)-(25) (the linear spring-dashpot model used by Mishra for
// granular materials, the paper's ref. 12; Cundall & Strack 1979):
//   spring  F_s = k (d - |x_ij|) n,              n = x_ij / |x_ij|, on overlap d - |x_ij| > 0     (23)
//   damper  F_d = -eta (v_ij . n) n                                                             (24)
//   shear   F_t = -k_t v_ij,t,  v_ij,t = v_ij - (v_ij . n) n                                    (25)
// with d the particle spacing (two particles touch when their centres are one spacing apart).
// Two bounds the paper leaves open, chosen here:
//   - the normal force never pulls (F_n = max(F_s + F_d, 0)): a dashpot that attracts at the end of a contact
//     glues bodies together, which is not what colliding solids do;
//   - the shear force is capped by Coulomb friction, |F_t| <= mu F_n: without the cap a fast sliding contact
//     would grip with any force, and rolling bodies would stop dead.
// Pairs of particles of one body never contact (a rigid body holds itself together; an elastic body through
// its own stress), and neither do fluid particles (they interact through pressure).
#pragma once

#include "core/neighbors.hpp"
#include "core/particles.hpp"

namespace aortasph {

struct ContactParams {
  double k = 0.0;            // N/m
  double eta = 0.0;          // N s/m
  double shear = 0.0;        // N s/m
  double friction = 0.5;     // Coulomb mu
  double distance = 0.0;     // contact distance d [m]
  bool skip_shells = false;  // pairs with a shell particle: left to sim/solid/shell_contact.hpp
};

// Force of contact on particle i from particle j (x_ij = x_i - x_j). Antisymmetric: force(i,j) = -force(j,i)
// bit for bit, so momentum is conserved exactly.
Vec3 contact_force(const ContactParams& c, const Vec3& xij, const Vec3& vij);

// Adds to f[i] the contact forces on every non-fluid particle i (gathered over its neighbours), and to
// moment[i] their moment about x_i when each acts at the contact point, midway between the two centres:
// sum_j (x_j - x_i) / 2 x F_ij. A rigid body's torque sum then uses the contact points, so a pair's two
// forces have equal and opposite moments and angular momentum is conserved (with forces at the particle
// centres the shear force of eq. 25 would create angular momentum from nothing).
void contact_forces(const Particles& P, const NeighborSearch& nb, const ContactParams& c,
                    std::vector<Vec3>& f, std::vector<Vec3>& moment);

}  // namespace aortasph
