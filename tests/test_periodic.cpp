// Periodic domains (sim/core/periodic.hpp): the neighbour search across periodic faces, and plane Poiseuille
// flow between two no-slip plates driven by a body force (Morris, Fox & Zhu 1997, J. Comput. Phys. 136:214,
// sec. 5.1; the viscous term and the walls' extrapolated no-slip velocity of Adami, Hu & Adams 2012, eq. 22).
#include <catch2/catch.hpp>
#include <cmath>

#include "builders.hpp"
#include "core/neighbors.hpp"
#include "core/parallel.hpp"
#include "fluid/shifting.hpp"

using namespace aortasph;
using namespace aortasph::test;

TEST_CASE("periodic neighbour search finds the pairs across the faces, each once", "[periodic][neighbors]") {
  // A lattice filling a periodic box: every particle has the same neighbours as in an infinite lattice.
  const double dx = 0.1, len = 1.0;
  std::vector<Vec3> x;
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i) x.emplace_back((i + 0.5) * dx, (j + 0.5) * dx, (k + 0.5) * dx);
  const double radius = 0.26;  // 2.6 dx; the period holds 7 cells of radius / 2
  NeighborSearch nb;
  nb.set_periodic(Periodic({Vec3::Zero(), Vec3::Constant(len)}, {true, true, true}));
  nb.build(x, radius);
  // Lattice points within 2.6 dx of the origin, itself excluded.
  int expect = 0;
  for (int a = -3; a <= 3; ++a)
    for (int b = -3; b <= 3; ++b)
      for (int c = -3; c <= 3; ++c)
        if ((a || b || c) && (a * a + b * b + c * c) * dx * dx < radius * radius) ++expect;
  for (std::size_t i = 0; i < x.size(); ++i) {
    INFO("particle " << i);
    REQUIRE(static_cast<int>(nb.end(i) - nb.begin(i)) == expect);
    std::vector<uint32_t> js(nb.index().begin() + nb.begin(i), nb.index().begin() + nb.end(i));
    std::sort(js.begin(), js.end());
    REQUIRE(std::adjacent_find(js.begin(), js.end()) == js.end());  // no pair listed twice
  }
  // Only x periodic: a particle on the -x face sees the +x face, one on the -y face does not see the +y face.
  nb.set_periodic(Periodic({Vec3::Zero(), Vec3::Constant(len)}, {true, false, false}));
  nb.build(x, radius);
  auto neighbours_of = [&](std::size_t i, std::size_t j) {
    return std::find(nb.index().begin() + nb.begin(i), nb.index().begin() + nb.end(i), j) !=
           nb.index().begin() + nb.end(i);
  };
  const std::size_t corner = 0;            // (0.05, 0.05, 0.05)
  CHECK(neighbours_of(corner, 9));         // (0.95, 0.05, 0.05): across the x face
  CHECK_FALSE(neighbours_of(corner, 90));  // (0.05, 0.95, 0.05): across the y face, not periodic
  CHECK(nb.end(corner) - nb.begin(corner) < static_cast<uint32_t>(expect));
}

namespace {

// Plane Poiseuille flow at Re = u_max L / nu = 1: plates at y = 0 and y = L (3 wall layers each), periodic
// in x and z (8 spacings each), water-like fluid at rest driven by a body force F along x.
struct Poiseuille {
  double L = 1e-3, nu = 1e-6, F = 8e-3;  // u_max = F L^2 / (8 nu) = 1 mm/s
  double u_max() const { return F * L * L / (8 * nu); }
  double u(double y) const { return F / (2 * nu) * y * (L - y); }
  Scene scene(int across) const {
    const double dx = L / across, w = 8 * dx;
    Scene s;
    s.name = "poiseuille";
    s.spacing = dx;
    s.gravity = Vec3(F, 0, 0);
    s.domain = {Vec3(0, -4 * dx, 0), Vec3(w, L + 4 * dx, w)};
    s.periodic = {true, false, true};
    s.t_end = 1.0;
    s.max_dt = 1e-3;
    Material m = water(0.02);  // 20 u_max: Mach 0.05
    m.viscosity = nu;
    s.materials = {m, wall()};
    s.bodies = {box_body("fluid", 0, Vec3(0, 0, 0), Vec3(w, L, w)),
                box_body("floor", 1, Vec3(0, -3 * dx, 0), Vec3(w, 0, w)),
                box_body("lid", 1, Vec3(0, L, 0), Vec3(w, L + 3 * dx, w))};
    return s;
  }
};

// Largest |u_x - u(y)| over the fluid particles, over u_max; and the largest |u_y|, |u_z| over u_max.
std::pair<double, double> profile_error(const World& w, const Poiseuille& c) {
  const Particles& P = w.particles();
  double ex = 0, ecross = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    ex = std::max(ex, std::abs(P.v[i].x() - c.u(P.x[i].y())));
    ecross = std::max(ecross, std::max(std::abs(P.v[i].y()), std::abs(P.v[i].z())));
  }
  return {ex / c.u_max(), ecross / c.u_max()};
}

}  // namespace

TEST_CASE("plane Poiseuille flow between no-slip plates matches the parabola within 2 %",
          "[periodic][fluid][validation]") {
  // Morris et al. 1997 sec. 5.1 (their Re is lower; at Re = 1 the steady profile is the same parabola).
  // The slowest mode of the start-up decays as exp(-pi^2 nu t / L^2): 0.1 s here; after 0.6 s it is
  // 0.3 % of u_max.
  const Poiseuille c;
  double error[2] = {0, 0};
  for (const int across : {10, 20}) {
    World w(c.scene(across));
    w.advance_to(0.6, [] { return true; });
    const auto [ex, ecross] = profile_error(w, c);
    INFO(across << " spacings across: max |u - u_exact| / u_max = " << ex << ", cross flow " << ecross);
    error[across == 20] = ex;
    CHECK(ecross < 0.01);
    // Nothing left the periodic box.
    CHECK(w.count(Kind::Fluid) == static_cast<std::size_t>(across * 8 * 8));
  }
  // Measured at stop 21: 3.1 % at 10 spacings across, 1.5 % at 20 (first order: the walls' extrapolated
  // no-slip velocity).
  // Stop 51: 2.3 % and 1.1 %, since the fluid no longer starts with a hydrostatic density ramp along the
  // periodic x (the body force's direction; Periodic::across), which the density diffusion also kept.
  INFO("error at L/10 " << error[0] << ", at L/20 " << error[1]);
  CHECK(error[1] < 0.02);
  CHECK(error[0] / error[1] > 1.7);  // converging at about first order or better
}

TEST_CASE("gravity along a periodic axis leaves the density uniform along it, hydrostatic only across it",
          "[periodic][fluid]") {
  // The plane Poiseuille channel with gravity tilted: 8e-3 m/s^2 along the periodic x (the drive) and
  // 4e-3 m/s^2 down y (between the plates: 1 % denser at the floor than at the top, c0 = 0.02 m/s). At t = 0
  // the density follows only the y part, the equation of state's density at rho0 g_y depth; along x it is
  // uniform (until stop 51 it rose 1.6 % along the channel's 8 spacings, and the density diffusion's
  // hydrostatic term kept that ramp). After the first steps the flow is along +x and the density still
  // uniform along x.
  const Poiseuille c;
  Scene s = c.scene(10);
  s.gravity = Vec3(c.F, -4e-3, 0);
  s.materials[0].delta_sph = 0.1;  // the diffusion's hydrostatic term in play
  World w(s);
  const Particles& P = w.particles();
  const double rho0 = s.materials[0].density;
  const double top = c.L;  // the fluid's top face, half a spacing above its top row
  double worst_x = 0.0, worst_y = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    const double expect = w.fluid_params()[0].density(rho0 * 4e-3 * (top - P.x[i].y()));
    worst_y = std::max(worst_y, std::abs(P.rho[i] / expect - 1.0));
    for (std::size_t j = 0; j < P.size(); ++j)  // the same row (y), anywhere along x and z
      if (P.kind[j] == Kind::Fluid && std::abs(P.x[j].y() - P.x[i].y()) < 1e-9 * c.L)
        worst_x = std::max(worst_x, std::abs(P.rho[j] / P.rho[i] - 1.0));
  }
  INFO("t = 0: density within a row varies by " << worst_x << ", off the hydrostatic profile by " << worst_y);
  CHECK(worst_x < 1e-12);
  CHECK(worst_y < 1e-12);
  w.advance_to(0.05, [] { return true; });
  double spread = 0.0, ux = 0.0;
  int fluid = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    ux += P.v[i].x(), ++fluid;
    for (std::size_t j = 0; j < P.size(); ++j)
      if (P.kind[j] == Kind::Fluid && std::abs(P.x[j].y() - P.x[i].y()) < 0.25 * s.spacing)
        spread = std::max(spread, std::abs(P.rho[j] / P.rho[i] - 1.0));
  }
  INFO("t = 0.05 s: density spread within a layer " << spread << ", mean u_x " << ux / fluid);
  CHECK(ux > 0.0);
  CHECK(spread < 2e-4);  // before stop 51: 1.3e-3 (and 1.3e-2 within a row at t = 0)
}

TEST_CASE("a periodic run is bitwise identical for 1 and 2 threads", "[periodic][determinism][heavy]") {
  const Poiseuille c;
  uint64_t hash[2] = {0, 0};
  for (int t = 1; t <= 2; ++t) {
    set_threads(t);
    World w(c.scene(10));
    w.advance_to(0.05, [] { return true; });
    hash[t - 1] = state_hash(w);
  }
  set_threads(2);
  CHECK(hash[0] == hash[1]);
}

TEST_CASE("Taylor-Green vortex at Re = 1: kinetic energy decays as exp(-4 nu k^2 t) within 5 %",
          "[periodic][fluid][validation]") {
  // U = 0.01 m/s, lambda = 1 m, nu = 0.01 m^2/s (Re = U lambda / nu = 1), c0 = 1 m/s (Mach 0.01), with its
  // pressure field; over one decay time T = 1 / (4 nu k^2) = 0.63 s. Measured at stop 21: KE / exact at T =
  // 1.111 at lambda/10, 1.036 at lambda/20 (the viscous term, eq. 10 in Morris's form, dissipates a little
  // too little; second order in dx on this smooth field). At Re = 100 plain WCSPH breaks the vortex up
  // (docs/validation.md).
  TaylorGreen c;
  c.U = 0.01;
  const double T = 1.0 / c.decay_rate();
  double error[2] = {0, 0};
  for (const int across : {10, 20}) {
    World w(c.scene(across, 1.0, 0.0, 0.1));
    const double e0 = kinetic_energy(w);
    double worst = 0.0;
    for (int k = 1; k <= 5; ++k) {
      const double t = 0.2 * k * T;
      w.advance_to(t, [] { return true; });
      worst = std::max(worst, std::abs(kinetic_energy(w) / e0 / std::exp(-c.decay_rate() * t) - 1.0));
    }
    error[across == 20] = worst;
    CHECK(w.count(Kind::Fluid) == static_cast<std::size_t>(across * across * 8));
  }
  INFO("largest |KE / exact - 1| over one decay time: " << error[0] << " at lambda/10, " << error[1]
                                                        << " at lambda/20");
  CHECK(error[1] < 0.05);
  CHECK(error[0] / error[1] > 2.0);  // converging faster than first order
}

TEST_CASE("particle shifting leaves a uniformly moving periodic lattice undistorted, momentum unchanged",
          "[periodic][fluid]") {
  // A periodic box of fluid moving uniformly with shifting on (A = 2): an even lattice has no concentration
  // gradient, so it must translate undistorted (a wrong periodic image, or a gradient that is not zero on a
  // regular lattice, would shift particles), and the total momentum stays what it was (shifting moves
  // particles, never their velocities).
  TaylorGreen c;
  Scene s = c.scene(10, 10.0, 0.0, 0.1, 2.0);
  s.bodies[0].taylor_green.reset();
  s.bodies[0].velocity = Vec3(1.0, 0.5, 0.0);
  World w(s);
  const Particles& P = w.particles();
  Vec3 p0 = Vec3::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) p0 += P.m[i] * P.v[i];
  for (int k = 0; k < 50; ++k) w.step(w.stable_dt());
  Vec3 p1 = Vec3::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) p1 += P.m[i] * P.v[i];
  CHECK((p1 - p0).norm() <= 1e-12 * p0.norm());
  // A uniform lattice in uniform motion has no concentration gradient: it translates undistorted (every
  // particle keeps its offset to particle 0, up to the periodic wrap).
  double worst = 0.0;
  const Periodic per(s.domain, s.periodic);
  for (std::size_t i = 0; i < P.size(); ++i)
    worst = std::max(worst, (per.image((P.x[i] - P.x[0]) - (P.x0[i] - P.x0[0]))).norm());
  CHECK(worst < 1e-9);
}

TEST_CASE("the shift's density change is the change of the summation density, to first order",
          "[periodic][fluid]") {
  // With shifting_ale the continuity equation (fluid_density_rate) takes in each particle's last shift as a
  // velocity, v + dr / dt (fluid/shifting.hpp): its rate with the shifts less its rate without, times dt, is
  // delta rho_i = sum_j m_j (dr_i - dr_j) . grad_i W_ij. On a disordered lattice (a Taylor-Green vortex after
  // 40 steps, A = 2) that must be what moving every particle by its shift does to rho_i = sum_j m_j W_ij
  // (brute force over periodic images), up to second order in the shift: with the shifts scaled by 1/2 the
  // mismatch falls about four times. A sign error or a missing dr_j would leave a mismatch as large as
  // delta rho itself.
  TaylorGreen c;
  Scene s = c.scene(10, 10.0, 0.0, 0.1, 2.0);
  s.materials[0].shifting_ale = true;
  World w(s);
  for (int k = 0; k < 40; ++k) w.step(w.stable_dt());
  const double dx = w.scene().spacing, dt = w.stable_dt();
  const Particles& P = w.particles();
  const FluidContext& ctx = w.fluid_context();
  std::vector<Vec3> shift;
  fluid_shifting(P, w.neighbors(), ctx, dx, dt, shift);
  const std::size_t n = P.size();
  // delta rho from the continuity equation, for the shifts scaled by `scale`.
  auto continuity = [&](double scale) {
    Particles copy = P;
    copy.shift = shift;
    for (Vec3& d : copy.shift) d *= scale;
    FluidContext with = ctx;
    with.shift_rate = 1.0 / dt;
    fluid_density_rate(copy, w.neighbors(), with);
    std::vector<double> drho = copy.drho;
    with.shift_rate = 0.0;
    fluid_density_rate(copy, w.neighbors(), with);
    for (std::size_t i = 0; i < n; ++i) drho[i] = (drho[i] - copy.drho[i]) * dt;
    return drho;
  };
  auto summation = [&](double scale) {
    std::vector<double> rho(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) {
        const double r = ctx.separation(P.x[i] + scale * shift[i], P.x[j] + scale * shift[j]).norm();
        if (r < ctx.kernel.support) rho[i] += P.m[j] * ctx.kernel.W(r);
      }
    return rho;
  };
  const std::vector<double> drho = continuity(1.0), drho_half = continuity(0.5);
  const std::vector<double> rho0 = summation(0.0), rho1 = summation(1.0), rho_half = summation(0.5);
  double size = 0.0, miss = 0.0, miss_half = 0.0, largest_shift = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    size = std::max(size, std::abs(drho[i]));
    miss = std::max(miss, std::abs(rho1[i] - rho0[i] - drho[i]));
    miss_half = std::max(miss_half, std::abs(rho_half[i] - rho0[i] - drho_half[i]));
    largest_shift = std::max(largest_shift, shift[i].norm());
  }
  INFO("largest shift " << largest_shift / dx << " dx; largest |delta rho| " << size << " kg/m^3; mismatch "
                        << miss << " (shifts halved: " << miss_half << ")");
  REQUIRE(largest_shift > 1e-3 * dx);
  CHECK(miss < 0.05 * size);
  CHECK(miss_half < 0.35 * miss);
}

TEST_CASE("particle shifting carried by the force loop equals the stand-alone pass, bit for bit",
          "[periodic][fluid]") {
  // World::step has fluid_forces carry the shift's sums (one neighbour pass fewer, issue 18); the
  // stand-alone fluid_shifting is the reference. A Taylor-Green vortex after 40 steps (a disordered lattice:
  // the shifts are not zero) at A = 2: both from the same state must agree exactly, for 1 and 2 threads.
  TaylorGreen c;
  World w(c.scene(10, 10.0, 0.0, 0.1, 2.0));
  for (int k = 0; k < 40; ++k) w.step(w.stable_dt());
  const double dx = w.scene().spacing, dt = w.stable_dt();
  const int before = max_threads();
  for (const int threads : {1, 2}) {
    set_threads(threads);
    std::vector<Vec3> ref, fused;
    fluid_shifting(w.particles(), w.neighbors(), w.fluid_context(), dx, dt, ref);
    Particles copy = w.particles();
    const ShiftRequest req{dx, dt, &fused};
    fluid_forces(copy, w.neighbors(), w.fluid_context(), &req);
    REQUIRE(fused.size() == ref.size());
    std::size_t moved = 0, differ = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      moved += ref[i].norm() > 1e-6 * dx;
      differ += fused[i] != ref[i];
    }
    INFO(threads << " thread(s): " << moved << " of " << ref.size() << " shifted");
    CHECK(moved > ref.size() / 2);
    CHECK(differ == 0);
  }
  set_threads(before);
}

namespace {

// The Taylor-Green box with the transport-velocity formulation (sim/fluid/transport_velocity.hpp) as Adami,
// Hu & Adams 2013 run it: density summation, a linear equation of state (gamma = 1), p_b = rho0 c0^2.
Scene transport_scene(const TaylorGreen& c, int across, double c0) {
  Scene s = c.scene(across, c0, 0.0, 0.0);
  Material& m = s.materials[0];
  m.eos_exponent = 1.0;
  m.density_summation = true;
  m.transport_velocity_pb = m.density * c0 * c0;
  return s;
}

}  // namespace

TEST_CASE(
    "Taylor-Green vortex at Re = 100 with the transport velocity: KE within 2 % over 0.2 T, second order",
    "[periodic][fluid][validation][transport]") {
  // U = 1 m/s, lambda = 1 m, nu = 0.01 m^2/s (Re = 100), c0 = 10 m/s. Measured (stop 23, docs/validation.md):
  // KE / exact at 0.2 T = 0.127 s is 1.051 at lambda/10 and 1.013 at lambda/20 (plain WCSPH at lambda/20:
  // 0.951). With Adami et al.'s p_b on the exact lattice issue 20's target, within 5 % over one decay time T,
  // is missed: the vortex breaks up between 0.2 T and 0.3 T (KE / exact 0.71 at 0.3 T at lambda/20; the
  // lattice strings out, docs/validation.md), so this test holds it to the first fifth of T. The set-up
  // that meets the target (p_b = 2 rho0 c0^2, a jittered start) is the next test case.
  const TaylorGreen c;
  const double T = 1.0 / c.decay_rate();
  double error[2] = {0, 0};
  for (const int across : {10, 20}) {
    World w(transport_scene(c, across, 10.0));
    const double e0 = kinetic_energy(w);
    double worst = 0.0;
    for (int k = 1; k <= 2; ++k) {
      const double t = 0.1 * k * T;
      w.advance_to(t, [] { return true; });
      worst = std::max(worst, std::abs(kinetic_energy(w) / e0 / std::exp(-c.decay_rate() * t) - 1.0));
    }
    error[across == 20] = worst;
    const Particles& P = w.particles();
    CHECK(w.count(Kind::Fluid) == static_cast<std::size_t>(across * across * 8));
    // Momentum: the background pressure moves particles, never their velocities, and the extra stress is
    // antisymmetric in a pair; the vortex has none to start with.
    Vec3 p = Vec3::Zero();
    double scale = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      p += P.m[i] * P.v[i];
      scale += P.m[i] * P.v[i].norm();
    }
    CHECK(p.norm() <= 1e-10 * scale);
  }
  INFO("largest |KE / exact - 1| over 0.2 T: " << error[0] << " at lambda/10, " << error[1]
                                               << " at lambda/20");
  CHECK(error[1] < 0.02);
  CHECK(error[0] / error[1] > 2.5);  // about second order (measured 3.8)
}

TEST_CASE(
    "Taylor-Green vortex at Re = 100, transport velocity with p_b = 2 rho0 c0^2 on a jittered lattice: KE "
    "within 6.5 % over half a decay time at lambda/10",
    "[periodic][fluid][validation][transport]") {
  // Issue 20's target (within 5 % of exp(-4 nu k^2 t) over T = 1 / (4 nu k^2)) is met at lambda/20 with the
  // background pressure doubled and the lattice jittered by 0.2 dx (bodies[].jitter): KE / exact within 2.9 %
  // there (scripts/validate_taylor_green.sh; 0.99 at T), 0.6 % at lambda/40, 6.1 % at lambda/10 (at 0.2 T;
  // 1.006 at T). This test holds lambda/10 over the first half of T, where its worst error lies (lambda/20
  // over T is 1.4 million particle-steps, too long for CTest). On the exact lattice the same run ends at 0.80
  // of the exact energy at lambda/20, with p_b = rho0 c0^2 and the jitter at 0.90 (docs/validation.md).
  const TaylorGreen c;
  const double T = 1.0 / c.decay_rate();
  Scene s = transport_scene(c, 10, 10.0);
  s.materials[0].transport_velocity_pb = 2.0 * s.materials[0].density * 10.0 * 10.0;
  s.bodies[0].jitter = 0.2;
  World w(s);
  const Particles& P = w.particles();
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < P.size(); ++i) p += P.m[i] * P.v[i];
    return p;
  };
  const Vec3 p0 = momentum();
  const double e0 = kinetic_energy(w);
  double worst = 0.0, last = 0.0, scale = 0.0;
  for (int k = 1; k <= 5; ++k) {
    const double t = 0.1 * k * T;
    w.advance_to(t, [] { return true; });
    last = kinetic_energy(w) / e0 / std::exp(-c.decay_rate() * t);
    worst = std::max(worst, std::abs(last - 1.0));
  }
  for (std::size_t i = 0; i < P.size(); ++i) scale += P.m[i] * P.v[i].norm();
  INFO("largest |KE / exact - 1| over T / 2: " << worst << ", KE / exact at T / 2: " << last);
  CHECK(w.count(Kind::Fluid) == 800u);
  CHECK(worst < 0.065);                 // measured 0.061 (at 0.2 T)
  CHECK(std::abs(last - 1.0) < 0.015);  // measured 1.012 (the noise of the start has decayed)
  CHECK((momentum() - p0).norm() <= 1e-10 * scale);
}

TEST_CASE("a fluid body's jitter moves each particle off its site by at most jitter * dx per axis",
          "[periodic][fluid][scene]") {
  // bodies[].jitter (World::jitter_points): offsets within +-jitter dx along each axis, spread over that
  // range, the same in two constructions, wrapped into the periodic box; the initial flow is the vortex at
  // the moved positions.
  const TaylorGreen c;
  Scene s = c.scene(10, 10.0, 0.0, 0.0);
  const World lattice(s);
  s.bodies[0].jitter = 0.2;
  const World a(s), b(s);
  const Particles &L = lattice.particles(), &P = a.particles();
  REQUIRE(P.size() == L.size());
  const double dx = s.spacing, k = 2.0 * M_PI / c.lambda;
  const Periodic per(s.domain, s.periodic);
  std::vector<std::size_t> site(L.size());  // the lattice world's index of each particle id (both are sorted)
  for (std::size_t i = 0; i < L.size(); ++i) site[L.id[i]] = i;
  double largest = 0.0, smallest = 1.0, flow = 0.0;
  Vec3 mean = Vec3::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec3 d = per.image(P.x[i] - L.x[site[P.id[i]]]) / dx;
    largest = std::max(largest, d.cwiseAbs().maxCoeff());
    smallest = std::min(smallest, d.cwiseAbs().maxCoeff());
    mean += d / static_cast<double>(P.size());
    CHECK(P.x[i] == b.particles().x[i]);
    for (int ax = 0; ax < 3; ++ax) {
      CHECK(P.x[i][ax] >= s.domain.min[ax]);
      CHECK(P.x[i][ax] < s.domain.max[ax]);
    }
    const double x = k * P.x[i].x(), y = k * P.x[i].y();
    flow = std::max(flow,
                    (P.v[i] - c.U * Vec3(std::sin(x) * std::cos(y), -std::cos(x) * std::sin(y), 0.0)).norm());
  }
  INFO("largest offset " << largest << " dx, smallest largest-axis offset " << smallest << " dx, mean "
                         << mean.transpose());
  CHECK(largest <= 0.2 + 1e-12);
  CHECK(largest > 0.19);  // 2400 draws fill the range
  CHECK(smallest < 0.1);
  CHECK(mean.norm() < 0.02);
  CHECK(flow < 1e-12);
}

TEST_CASE(
    "the transport velocity leaves a uniformly moving lattice undistorted and runs the same on 1 and 2 "
    "threads",
    "[periodic][fluid][transport][determinism]") {
  const TaylorGreen c;
  {
    // An even lattice has no discrete background-pressure gradient: it must translate undistorted.
    Scene s = transport_scene(c, 10, 10.0);
    s.bodies[0].taylor_green.reset();
    s.bodies[0].velocity = Vec3(1.0, 0.5, 0.0);
    World w(s);
    const Particles& P = w.particles();
    for (int k = 0; k < 30; ++k) w.step(w.stable_dt());
    double worst = 0.0;
    const Periodic per(s.domain, s.periodic);
    for (std::size_t i = 0; i < P.size(); ++i)
      worst = std::max(worst, (per.image((P.x[i] - P.x[0]) - (P.x0[i] - P.x0[0]))).norm());
    CHECK(worst < 1e-9);
  }
  // The vortex with the formulation on: bitwise the same state for 1 and 2 threads.
  uint64_t hash[2] = {0, 0};
  for (int t = 1; t <= 2; ++t) {
    set_threads(t);
    World w(transport_scene(c, 10, 10.0));
    for (int k = 0; k < 25; ++k) w.step(w.stable_dt());
    hash[t - 1] = state_hash(w);
  }
  set_threads(2);
  CHECK(hash[0] == hash[1]);
}

TEST_CASE("blood at arterial pressure pairs up at h = 1.3 dx and not at h = 1.2 dx",
          "[periodic][fluid][.validation]") {
  // The pairing instability of the cubic spline (paper eq. 5) with many neighbours (Dehnen & Aly 2012, MNRAS
  // 425:1068): a periodic box of the physio scene's blood (c0 = 40 m/s, shifting 2, Riemann dissipation 3)
  // at 15 kPa, an aortic pressure, from a lattice jittered by 0.1 dx, at rest. At h = 1.3 dx (74 neighbours
  // per support) the particles fall into pairs within 25 ms, as the physio scene's blood did wherever it
  // was slow (42 % of the aorta's particles closer than dx/2 by 70 ms, docs/validation.md "Stop 47"); at
  // 1.2 dx (58) they stay apart. Measured: 40.8 % closer than dx/2 at 25 ms at 1.3, none at 1.2; at 2 kPa
  // (a box of 12 dx, 30 ms) neither pairs. Hidden from the suite (scripts/validate.sh runs it): 3.5 min on a
  // loaded 2-core host.
  auto pair_share = [](double ratio) {
    const double dx = 0.001, side = 10 * dx;
    Scene s;
    s.name = "pair_box";
    s.spacing = dx;
    s.smoothing_ratio = ratio;
    s.gravity = Vec3::Zero();
    s.domain = {Vec3::Zero(), Vec3(side, side, side)};
    s.periodic = {true, true, true};
    s.t_end = 0.025;
    s.max_dt = 1e-3;
    Material m = water(40.0);
    m.name = "blood";
    m.density = 1060.0;
    m.viscosity = 3.3e-6;
    m.background_pressure = 15000.0;
    m.shifting = 2.0;
    m.riemann_dissipation = 3.0;
    s.materials = {m};
    Body b = box_body("blood", 0, Vec3::Zero(), Vec3(side, side, side));
    b.jitter = 0.1;
    s.bodies = {b};
    World w(s);
    w.advance_to(s.t_end, [] { return true; });
    const Particles& P = w.particles();
    const Periodic per(s.domain, s.periodic);
    std::size_t close = 0;
    for (std::size_t i = 0; i < P.size(); ++i)
      for (std::size_t j = 0; j < P.size(); ++j)
        if (j != i && per.image(P.x[i] - P.x[j]).squaredNorm() < 0.25 * dx * dx) {
          ++close;
          break;
        }
    REQUIRE(P.size() == 1000);
    return static_cast<double>(close) / static_cast<double>(P.size());
  };
  const double wide = pair_share(1.3), narrow = pair_share(1.2);
  INFO("particles closer than dx/2 at 25 ms: " << 100 * wide << " % at h = 1.3 dx, " << 100 * narrow
                                               << " % at 1.2 dx");
  CHECK(wide > 0.15);
  CHECK(narrow < 0.01);
}
