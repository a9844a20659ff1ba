// Rigid bodies made of particles, paper section 3.3, eqs. (19)-(22) (after Baraff's "Physically based
// modeling" notes, the paper's refs. 10, 11):
//   dP/dt = sum_i F_i                       (19)
//   dL/dt = sum_i (r_i - r_cog) x F_i        (20)
//   omega = I(t)^-1 L                        (21)
//   I(t)^-1 = R(t) I(0)^-1 R(t)^T            (22)
// The particles carry no state of their own: their positions and velocities follow from the body's.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "scene.hpp"

namespace aortasph {

using Mat3 = Eigen::Matrix3d;

struct RigidBody {
  int body = 0;  // index into the scene's bodies
  double mass = 0.0;
  Vec3 com0 = Vec3::Zero();      // centre of mass at t = 0 (particles' body-frame origin)
  Mat3 inertia0 = Mat3::Zero();  // about the centre of mass, world axes at t = 0
  Mat3 inv_inertia0 = Mat3::Zero();
  // State.
  Vec3 com = Vec3::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // body to world
  Vec3 P = Vec3::Zero();                                  // linear momentum
  Vec3 L = Vec3::Zero();                                  // angular momentum about the centre of mass
  // Sums of the current step.
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();

  Mat3 rotation() const { return q.toRotationMatrix(); }
  Vec3 velocity() const { return P / mass; }
  // eqs. (21), (22)
  Vec3 omega() const {
    const Mat3 R = rotation();
    return R * inv_inertia0 * R.transpose() * L;
  }
  double kinetic_energy() const { return 0.5 * P.squaredNorm() / mass + 0.5 * L.dot(omega()); }
  // Where a particle that sat at x0 at t = 0 is now, and how fast it moves.
  Vec3 position_of(const Vec3& x0) const { return com + rotation() * (x0 - com0); }
};

// Mass, centre of mass and inertia tensor of point masses m at x, each also carrying the inertia of its own
// cube of side dx (m dx^2 / 6 about every axis), so a box of particles has exactly the inertia of the solid
// box. Initial velocity v and angular velocity w (about the centre of mass).
RigidBody make_rigid_body(int body, const std::vector<Vec3>& x, double m, double dx, const Vec3& v,
                          const Vec3& w);

// One step of eqs. (19)-(22) with the force and torque already summed (gravity included): symplectic Euler,
// P and L first, then the centre of mass and the orientation with the new velocities. The orientation
// advances by the exact rotation of angle |omega| dt about omega (a unit quaternion, no drift from
// normalisation). `kick` is the length of the P and L update: dt, or the variable-step leapfrog's mean of the
// previous and this step (World::integrate).
void advance_rigid_body(RigidBody& b, double dt, double kick);
inline void advance_rigid_body(RigidBody& b, double dt) {
  advance_rigid_body(b, dt, dt);
}

}  // namespace aortasph
