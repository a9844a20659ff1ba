#include "rigid/rigid_body.hpp"

namespace aortasph {

RigidBody make_rigid_body(int body, const std::vector<Vec3>& x, double m, double dx, const Vec3& v,
                          const Vec3& w) {
  RigidBody b;
  b.body = body;
  b.mass = m * static_cast<double>(x.size());
  for (const Vec3& p : x) b.com0 += p;
  b.com0 /= static_cast<double>(x.size());
  const double own = m * dx * dx / 6.0;  // a particle's own cube about its centre
  for (const Vec3& p : x) {
    const Vec3 r = p - b.com0;
    b.inertia0 += m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose()) + own * Mat3::Identity();
  }
  b.inv_inertia0 = b.inertia0.inverse();
  b.com = b.com0;
  b.P = b.mass * v;
  b.L = b.inertia0 * w;
  return b;
}

void advance_rigid_body(RigidBody& b, double dt, double kick) {
  b.P += kick * b.force;   // eq. (19)
  b.L += kick * b.torque;  // eq. (20)
  b.com += dt * b.velocity();
  const Vec3 w = b.omega();  // eqs. (21), (22) with the new L and the old orientation
  const double angle = w.norm() * dt;
  if (angle > 0.0) {
    const Eigen::Quaterniond dq(Eigen::AngleAxisd(angle, w.normalized()));
    b.q = (dq * b.q).normalized();
  }
}

}  // namespace aortasph
