// Fluid on both sides of a one-layer shell (sim/boundary/shell_coupling.hpp, sim/fluid/shell_wall.hpp):
// a stiff sheet holding a pressure difference without a leak, a water column on a clamped plate (one side),
// the same plate between two columns (both sides).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "builders.hpp"
#include "core/parallel.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

Material sheet_material(double E, double nu, double t, double rho, double damping) {
  Material m;
  m.name = "sheet";
  m.type = MaterialType::Shell;
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.thickness = t;
  m.hourglass = 0.05;
  m.shell_damping = damping;
  return m;
}

// A square sheet of side w at height y (normal +y) across a square shaft [0, w]^2 in x and z, its edge rows
// (dx / 2 from the shaft's walls) clamped.
Body clamped_sheet(int material, double w, double y, double dx) {
  Body b;
  b.name = "sheet";
  b.material = material;
  b.shape.kind = ShapeKind::Rectangle;
  b.shape.center = Vec3(0.5 * w, y, 0.5 * w);
  b.shape.size = {w, w};  // particles at dx / 2 .. w - dx / 2, on the fluid's lattice; edge rows clamped
  b.shape.normal = Vec3::UnitY();
  b.shape.u_axis = Vec3::UnitX();
  const double e = 0.75 * dx, big = 10.0;
  b.shell_fixed = {Box{Vec3(-big, y - e, -big), Vec3(e, y + e, big)},
                   Box{Vec3(w - e, y - e, -big), Vec3(big, y + e, big)},
                   Box{Vec3(-big, y - e, -big), Vec3(big, y + e, e)},
                   Box{Vec3(-big, y - e, w - e), Vec3(big, y + e, big)}};
  return b;
}

// A square shaft [0, w] x [0, top] x [0, w] (walls, open at the top) with water below a clamped sheet at
// y = y_sheet (from the floor) and a column of height h_up above it.
Scene sheet_in_shaft(double w, double y_sheet, double h_up, double dx, const Material& sheet, double c0) {
  Scene s;
  s.name = "sheet_in_shaft";
  s.spacing = dx;
  s.gravity = Vec3(0, -9.81, 0);
  const double top = y_sheet + h_up + 4 * dx;
  s.domain = {Vec3(-0.5, -0.5, -0.5), Vec3(w + 0.5, top + 0.5, w + 0.5)};
  s.max_dt = 1e-3;
  s.cfl = 0.25;
  s.max_density_error = 0.05;
  s.materials = {water(c0), wall(), sheet};
  s.bodies = {box_body("below", 0, Vec3(0, 0, 0), Vec3(w, y_sheet, w)),
              box_body("above", 0, Vec3(0, y_sheet, 0), Vec3(w, y_sheet + h_up, w)),
              container("shaft", 1, Vec3(0, 0, 0), Vec3(w, top, w), {"+y"}),
              clamped_sheet(2, w, y_sheet, dx)};
  return s;
}

// Mean pressure of body b's fluid particles within `band` of the plane y = y0.
double mean_pressure(const World& w, int body, double y0, double band) {
  const Particles& P = w.particles();
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (P.kind[i] == Kind::Fluid && P.body[i] == body && std::abs(P.x[i].y() - y0) < band) {
      sum += P.p[i];
      ++n;
    }
  return n > 0 ? sum / n : 0.0;
}

// Particles of body b on the wrong side of the sheet's current mid-plane height at their (x, z) (the sheet
// sags little: the nearest sheet particle's height is the plane there).
std::size_t wrong_side(const World& w, int body, bool above) {
  const Particles& P = w.particles();
  std::size_t n = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid || P.body[i] != body) continue;
    double best = 1e30, y = 0.0;
    for (std::size_t j = 0; j < P.size(); ++j)
      if (P.kind[j] == Kind::Shell) {
        const double d = std::hypot(P.x[j].x() - P.x[i].x(), P.x[j].z() - P.x[i].z());
        if (d < best) best = d, y = P.x[j].y();
      }
    if (above ? P.x[i].y() < y : P.x[i].y() > y) ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("shell-fluid: a clamped stiff sheet holds a 10 kPa difference without a leak", "[shell_fluid]") {
  // 1.02 m of water over a fixed sheet (rho g h = 10 kPa), a closed chamber of water below it. What is tested
  // is the fluid's side of the coupling: the column stands on the sheet as on a wall, and nothing of it, mass
  // or pressure, reaches the chamber.
  const double dx = 0.05, w = 0.3, y_sheet = 0.3, h_up = 1.02;
  Scene s = sheet_in_shaft(w, y_sheet, h_up, dx, sheet_material(5e6, 0.3, 0.05, 1000.0, 20.0), 40.0);
  s.bodies[3].shell_fixed.push_back(Box{Vec3(-1, y_sheet - 0.01, -1), Vec3(1, y_sheet + 0.01, 1)});
  World world(s);
  REQUIRE(world.shells().size() == 36);
  const double band = 2.0 * dx;
  auto above = [&] { return mean_pressure(world, 1, y_sheet, band); };
  auto below = [&] { return mean_pressure(world, 0, y_sheet, band); };
  const double dp0 = above() - below();
  // The same column on a plain wall floor (3 layers of wall particles): the reference for what the sheet
  // must reproduce.
  Scene f = s;
  f.bodies.erase(f.bodies.begin() + 3);
  f.bodies.erase(f.bodies.begin());
  f.bodies.push_back(box_body("floor", 1, Vec3(0, y_sheet - 3 * dx, 0), Vec3(w, y_sheet, w)));
  World floor(f);
  // And the chamber under a plain wall ceiling.
  Scene c = s;
  c.bodies.erase(c.bodies.begin() + 3);
  c.bodies.erase(c.bodies.begin() + 1);
  c.bodies.push_back(box_body("ceiling", 1, Vec3(0, y_sheet, 0), Vec3(w, y_sheet + 3 * dx, w)));
  World ceiling(c);
  // Means over 0.1 s (the column's acoustic period 4 h / c0 is 0.1 s).
  double sum_above = 0.0, sum_floor = 0.0, sum_below = 0.0, sum_ceiling = 0.0;
  const int samples = 20;
  for (int k = 1; k <= samples; ++k) {
    world.advance_to(0.005 * k, [] { return true; });
    floor.advance_to(0.005 * k, [] { return true; });
    ceiling.advance_to(0.005 * k, [] { return true; });
    sum_above += above();
    sum_floor += mean_pressure(floor, 0, y_sheet, band);
    sum_below += below();
    sum_ceiling += mean_pressure(ceiling, 0, y_sheet, band);
  }
  const double dp = (sum_above - sum_below) / samples, dp_walls = (sum_floor - sum_ceiling) / samples;
  INFO("dp(0) = " << dp0 << " Pa, mean dp over 0.1 s = " << dp << " Pa; above the sheet "
                  << sum_above / samples << " Pa, on a wall floor " << sum_floor / samples << " Pa; below "
                  << sum_below / samples << " Pa, under a wall ceiling " << sum_ceiling / samples
                  << " Pa; crossings " << world.shell_crossings() << ", masked pairs "
                  << world.shell_masked_pairs() << ", steps " << world.steps());
  CHECK(world.shell_crossings() == 0);
  CHECK(wrong_side(world, 0, false) == 0);
  CHECK(wrong_side(world, 1, true) == 0);
  CHECK(world.shell_masked_pairs() > 0);
  // The difference is what two plain walls hold, and the column feels the sheet as it feels a wall.
  CHECK(std::abs(dp / dp_walls - 1.0) < 0.02);
  CHECK(std::abs(sum_above / sum_floor - 1.0) < 0.005);
}
