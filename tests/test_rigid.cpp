// Rigid bodies made of particles (paper eqs. 19-22) and particle contact (eqs. 23-25).
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <sstream>

#include "builders.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "io/probes.hpp"
#include "rigid/contact_dem.hpp"
#include "rigid/rigid_body.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

Material steel(double density) {
  Material m;
  m.name = "steel";
  m.type = MaterialType::Rigid;
  m.density = density;
  return m;
}

std::vector<Vec3> lattice_points(int n, double dx, auto&& inside) {
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const Vec3 p = dx * Vec3(i + 0.5, j + 0.5, k + 0.5);
        if (inside(p)) pts.push_back(p);
      }
  return pts;
}

// Total linear and angular momentum (about the origin) and kinetic energy of the rigid bodies.
struct RigidTotals {
  Vec3 P = Vec3::Zero(), L = Vec3::Zero();
  double E = 0.0;
};
RigidTotals rigid_totals(const World& w) {
  RigidTotals t;
  for (const RigidBody& b : w.rigid_bodies()) {
    t.P += b.P;
    t.L += b.com.cross(b.P) + b.L;
    t.E += b.kinetic_energy();
  }
  return t;
}

}  // namespace

TEST_CASE("inertia of a particle box and a particle sphere match the solids", "[rigid]") {
  const double dx = 0.01, m = 1.0;
  // Box 12 x 10 x 14 particles: the particles' own cubes make the lattice sum exact for a box.
  std::vector<Vec3> box;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 14; ++k) box.push_back(dx * Vec3(i + 0.5, j + 0.5, k + 0.5));
  const RigidBody b = make_rigid_body(0, box, m, dx, Vec3::Zero(), Vec3::Zero());
  const double M = m * box.size(), a = 0.12, bb = 0.10, c = 0.14;
  CHECK(b.inertia0(0, 0) == Approx(M * (bb * bb + c * c) / 12).epsilon(0.02));
  CHECK(b.inertia0(1, 1) == Approx(M * (a * a + c * c) / 12).epsilon(0.02));
  CHECK(b.inertia0(2, 2) == Approx(M * (a * a + bb * bb) / 12).epsilon(0.02));
  CHECK(std::abs(b.inertia0(0, 1)) < 1e-12 * b.inertia0(0, 0));
  CHECK(b.com0.isApprox(Vec3(0.06, 0.05, 0.07), 1e-12));

  // Sphere of 12 particles across (radius 6 dx): compare with 2/5 M R^2 for the same mass.
  const double R = 0.06;
  const Vec3 centre(R, R, R);
  const auto sphere = lattice_points(12, dx, [&](const Vec3& p) { return (p - centre).norm() <= R; });
  const RigidBody s = make_rigid_body(0, sphere, m, dx, Vec3::Zero(), Vec3::Zero());
  const double Ms = m * sphere.size();
  for (int d = 0; d < 3; ++d) {
    INFO("axis " << d << ": " << s.inertia0(d, d) << " vs " << 0.4 * Ms * R * R);
    CHECK(s.inertia0(d, d) == Approx(0.4 * Ms * R * R).epsilon(0.02));
  }
  // Particle volume against the solid's: the sampled sphere holds the right mass within 5 %.
  CHECK(sphere.size() * dx * dx * dx == Approx(4.0 / 3.0 * std::numbers::pi * R * R * R).epsilon(0.05));
}

TEST_CASE("torque-free rotation keeps |L| and energy, a tilted spin precesses", "[rigid]") {
  std::vector<Vec3> box;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 3; ++k) box.push_back(0.01 * Vec3(i, j, k));
  // Spin about a principal axis (the box's y axis).
  // About z, the axis of largest inertia (a spin about the intermediate axis y would be unstable: any
  // round-off grows, the tennis-racket effect).
  RigidBody b = make_rigid_body(0, box, 1.0, 0.01, Vec3::Zero(), Vec3(0, 0, 5));
  const double L0 = b.L.norm(), E0 = b.kinetic_energy();
  for (int k = 0; k < 10000; ++k) advance_rigid_body(b, 1e-3);
  CHECK(std::abs(b.L.norm() / L0 - 1) < 1e-6);
  CHECK(std::abs(b.kinetic_energy() / E0 - 1) < 1e-6);
  INFO("omega " << b.omega().transpose());
  CHECK((b.omega() - Vec3(0, 0, 5)).norm() < 5e-6);  // still spinning about z
  CHECK(std::abs(b.q.norm() - 1.0) < 1e-12);

  // Tilted axis: L is constant in the world frame, omega is not (the body precesses).
  RigidBody t = make_rigid_body(0, box, 1.0, 0.01, Vec3::Zero(), Vec3(1, 5, 2));
  const Vec3 Lt = t.L, w0 = t.omega();
  const double Et = t.kinetic_energy();
  double max_turn = 0.0;
  for (int k = 0; k < 10000; ++k) {
    advance_rigid_body(t, 1e-4);
    max_turn =
        std::max(max_turn, std::acos(std::clamp(t.omega().normalized().dot(w0.normalized()), -1.0, 1.0)));
  }
  CHECK((t.L - Lt).norm() == 0.0);
  CHECK(max_turn > 0.1);  // omega wandered by more than 0.1 rad
  CHECK(std::abs(t.kinetic_energy() / Et - 1) < 1e-3);
}

namespace {

// Reads a column of the DEM reference CSV for a damping ratio.
double dem_reference(double zeta, const std::string& column) {
  std::ifstream f(std::string(AORTASPH_TEST_DIR) + "/data/dem_linear_spring_dashpot_restitution.csv");
  std::string line, header;
  std::getline(f, line);  // source
  std::getline(f, header);
  std::vector<std::string> names;
  std::stringstream hs(header);
  for (std::string s; std::getline(hs, s, ',');) names.push_back(s);
  while (std::getline(f, line)) {
    std::stringstream ls(line);
    std::vector<double> v;
    for (std::string s; std::getline(ls, s, ',');) v.push_back(std::stod(s));
    if (std::abs(v[0] - zeta) < 1e-9)
      for (std::size_t c = 0; c < names.size(); ++c)
        if (names[c] == column) return v[c];
  }
  FAIL("no reference for zeta " << zeta << " column " << column);
  return 0;
}

}  // namespace

TEST_CASE("head-on contact of two one-particle bodies: restitution and duration", "[rigid][contact]") {
  // m_eff = 1 kg (two 2 kg particles), k = 1e5 N/m, closing speed 1 m/s, as in the reference CSV.
  const double dx = 0.01, m = 2.0;
  for (double zeta : {0.0, 0.1, 0.3, 0.5}) {
    Scene s;
    s.name = "dem";
    s.spacing = dx;
    s.gravity = Vec3::Zero();
    s.domain = {Vec3(-1, -1, -1), Vec3(1, 1, 1)};
    s.max_dt = 1e-3;
    s.materials = {steel(m / (dx * dx * dx))};
    s.contact.stiffness = 1e5;
    s.contact.damping = 2.0 * zeta * std::sqrt(1.0 * 1e5);
    s.bodies = {box_body("a", 0, Vec3(-0.03, 0, 0), Vec3(-0.02, dx, dx), Vec3(0.5, 0, 0)),
                box_body("b", 0, Vec3(0.02, 0, 0), Vec3(0.03, dx, dx), Vec3(-0.5, 0, 0))};
    World w(s);
    REQUIRE(w.particles().size() == 2);
    double t_start = -1, t_end = -1;
    while (w.time() < 0.2 && t_end < 0) {
      w.step(w.stable_dt());
      const double gap = (w.rigid_bodies()[1].com - w.rigid_bodies()[0].com).norm();
      if (t_start < 0 && gap < dx) t_start = w.time();
      if (t_start >= 0 && t_end < 0 &&
          w.rigid_bodies()[1].velocity().x() - w.rigid_bodies()[0].velocity().x() > 0 && gap >= dx)
        t_end = w.time();
    }
    REQUIRE(t_end > 0);
    const double e = w.rigid_bodies()[1].velocity().x() - w.rigid_bodies()[0].velocity().x();
    const double e_ref = dem_reference(zeta, "e_num_force_end");
    INFO("zeta " << zeta << ": e = " << e << " (reference " << e_ref << "), contact " << t_end - t_start
                 << " s");
    CHECK(e == Approx(e_ref).epsilon(0.02));
    // The contact ends when the force reaches zero, before the overlap does: duration between the two
    // columns.
    CHECK(t_end - t_start >= dem_reference(zeta, "tc_num_force_end_s") * 0.98);
    CHECK(t_end - t_start <= dem_reference(zeta, "tc_num_overlap_end_s") * 1.02);
  }
}

TEST_CASE("off-axis collision of two boxes: momentum, angular momentum, energy, spin",
          "[rigid][contact][long]") {
  const double dx = 0.01;
  Scene s;
  s.name = "boxes";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-2, -2, -2), Vec3(2, 2, 2)};
  s.materials = {steel(1000)};
  s.contact = {5e3, 2.0, 1.0, 0.5};
  s.bodies = {box_body("left", 0, Vec3(-0.16, 0.0, 0), Vec3(-0.06, 0.1, 0.05), Vec3(1, 0, 0)),
              box_body("right", 0, Vec3(0.06, 0.05, 0), Vec3(0.16, 0.15, 0.05), Vec3(-1, 0, 0))};
  World w(s);
  const RigidTotals t0 = rigid_totals(w);
  double E_max = t0.E;
  while (w.time() < 0.2) {
    w.step(w.stable_dt());
    E_max = std::max(E_max, rigid_totals(w).E);
  }
  const RigidTotals t1 = rigid_totals(w);
  const double pscale = std::abs(w.rigid_bodies()[0].mass) * 1.0;  // |P| of one body
  INFO("dP = " << (t1.P - t0.P).norm() / pscale << ", dL = " << (t1.L - t0.L).norm() << ", E " << t0.E
               << " -> " << t1.E);
  CHECK((t1.P - t0.P).norm() / pscale < 1e-9);
  // Angular momentum: every contact force acts at the contact point of its pair (contact_dem.hpp), so the
  // torques of a pair cancel and the symplectic update keeps sum(com x P + L) exact up to round-off.
  const double Lscale = w.rigid_bodies()[0].mass * 0.1 * 1.0;  // |P| times the 0.05 m offset, doubled
  CHECK((t1.L - t0.L).norm() / Lscale < 1e-9);
  // Kinetic energy never rises above its initial value (during contact some sits in the springs), and the
  // dashpot took some.
  CHECK(E_max <= t0.E * (1 + 1e-12));
  CHECK(t1.E < t0.E);
  // Both spin afterwards. The left box is hit at its top (force -x), the right one at its bottom (force +x):
  // both torques point along +z, so both turn counter-clockwise. (The "opposite senses" is not what
  // equal and opposite forces at one contact point do for this geometry; the test asserts the physics.)
  const double w0 = w.rigid_bodies()[0].omega().z(), w1 = w.rigid_bodies()[1].omega().z();
  INFO("spins " << w0 << ", " << w1);
  CHECK(w0 > 0.5);
  CHECK(w1 > 0.5);
  // And they separate again.
  CHECK(w.rigid_bodies()[1].velocity().x() - w.rigid_bodies()[0].velocity().x() > 0.0);
}

TEST_CASE("rigid bodies in fluid: bitwise identical for 1 and 2 threads", "[rigid][determinism][heavy]") {
  const double dx = 0.01;
  Scene s = fluid_cubes(dx);
  s.materials.push_back(steel(3000));
  s.contact = {1e4, 2.0, 1.0, 0.5};
  s.bodies.push_back(box_body("block", 1, Vec3(-0.02, -0.15, -0.02), Vec3(0.02, -0.08, 0.02), Vec3(0, 1, 0)));
  std::vector<double> first;
  for (int t = 1; t <= 2; ++t) {
    set_threads(t);
    World w(s);
    for (int k = 0; k < 150; ++k) w.step(w.stable_dt());
    const RigidBody& b = w.rigid_bodies()[0];
    std::vector<double> state = {b.com.x(), b.com.y(), b.com.z(), b.P.x(),
                                 b.P.y(),   b.L.x(),   b.L.z(),   b.q.w()};
    for (const Vec3& v : w.particles().v) state.push_back(v.x() + v.y() + v.z());
    if (t == 1)
      first = state;
    else
      CHECK(state == first);
  }
  set_threads(2);
}

TEST_CASE("fluid hits a rigid block without gravity: total momentum is conserved", "[rigid][fluid][long]") {
  const double dx = 0.01;
  Scene s;
  s.name = "splash";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-1, -1, -1), Vec3(1, 1, 1)};
  s.materials = {water(20.0), steel(2000)};
  s.contact = {1e4, 2.0, 1.0, 0.5};
  s.bodies = {box_body("water", 0, Vec3(-0.15, -0.05, -0.05), Vec3(-0.03, 0.05, 0.05), Vec3(1.5, 0, 0)),
              box_body("block", 1, Vec3(0.0, -0.03, -0.03), Vec3(0.04, 0.04, 0.03))};
  World w(s);
  auto total = [&]() {
    Vec3 p = Vec3::Zero();
    double scale = 0.0;
    const Particles& P = w.particles();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.kind[i] == Kind::Fluid) {
        p += P.m[i] * P.v[i];
        scale += P.m[i] * P.v[i].norm();
      }
    p += w.rigid_bodies()[0].P;
    return std::pair{p, scale};
  };
  const auto [p0, scale] = total();
  while (w.time() < 0.08) w.step(w.stable_dt());
  const auto [p1, unused] = total();
  const double vblock = w.rigid_bodies()[0].velocity().x();
  INFO("block speed " << vblock << ", momentum change " << (p1 - p0).norm() / scale);
  CHECK(vblock > 0.05);                     // the fluid pushed the block
  CHECK((p1 - p0).norm() / scale < 1e-12);  // and lost exactly what the block gained
}

namespace {

// A 6 x 6 x 4 cm block of the given density dropped from just above a water tank (14 cm deep, dx = 1 cm) and
// left for 0.45 s: where its centre ends up, and no fluid particle inside it.
void drop_block(double density) {
  const double dx = 0.01;
  Scene s;
  s.name = "buoyancy";
  s.spacing = dx;
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.3, 0.5, 0.2)};
  s.materials = {water(20.0), wall(), steel(density)};
  s.contact = {200.0, 0.5, 0.2, 0.5};
  s.bodies = {box_body("water", 0, Vec3(0, 0, 0), Vec3(0.16, 0.14, 0.08)),
              container("tank", 1, Vec3(0, 0, 0), Vec3(0.16, 0.3, 0.08), {"+y"}),
              box_body("block", 2, Vec3(0.05, 0.15, 0.02), Vec3(0.11, 0.21, 0.06))};
  s.materials[0].artificial_viscosity = 0.05;
  World w(s);
  const double y0 = w.rigid_bodies()[0].com.y();
  while (w.time() < 0.45) w.step(w.stable_dt());
  const RigidBody& b = w.rigid_bodies()[0];
  INFO("density " << density << ": block centre from " << y0 << " to " << b.com.y() << ", vy "
                  << b.velocity().y());
  if (density > 1000) {
    CHECK(b.com.y() < 0.08);  // went down through the water, near the bottom
  } else {
    // Floats: 40 % of its 0.06 m height under the surface at 0.14 m puts its centre at 0.146 m.
    CHECK(b.com.y() > 0.13);
    CHECK(b.com.y() < 0.18);
  }
  // No fluid particle inside the block.
  const Particles& P = w.particles();
  const Mat3 Rt = b.rotation().transpose();
  int inside = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    const Vec3 local = Rt * (P.x[i] - b.com);
    if (std::abs(local.x()) < 0.02 && std::abs(local.y()) < 0.02 && std::abs(local.z()) < 0.01) ++inside;
  }
  CHECK(inside == 0);
}

}  // namespace

// Two test cases (not one loop) so that CTest runs them side by side: each takes about 45 s.
TEST_CASE("a dense block sinks through water, no fluid passes through it", "[rigid][fluid][.validation]") {
  drop_block(3000.0);
}

TEST_CASE("a light block floats on water, no fluid passes through it", "[rigid][fluid][.validation]") {
  drop_block(400.0);
}

TEST_CASE("bad rigid input: an empty body is refused naming it", "[rigid][bad-input]") {
  Scene s = fluid_cubes(0.01);
  s.materials.push_back(steel(3000));
  // Thinner than half a spacing: no lattice point inside.
  s.bodies.push_back(box_body("sliver", 1, Vec3(0.3, 0.3, 0.3), Vec3(0.304, 0.4, 0.4)));
  try {
    World w(s);
    FAIL("an empty rigid body was accepted");
  } catch (const SetupError& e) {
    CHECK(std::string(e.what()).find("sliver") != std::string::npos);
    CHECK(std::string(e.what()).find("no particle") != std::string::npos);
  }
}
