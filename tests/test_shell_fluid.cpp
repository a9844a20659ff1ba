// Fluid on both sides of a one-layer shell (sim/boundary/shell_coupling.hpp, sim/fluid/shell_wall.hpp):
// a stiff sheet holding a pressure difference without a leak, a water column on a clamped plate (one side),
// the same plate between two columns (both sides).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "builders.hpp"
#include "core/parallel.hpp"
#include "fluid/shifting.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

// A tank scene under gravity: water, walls and a sheet material; the domain is the tank [0, size] grown by
// 0.5 m on every side.
Scene tank_scene(const std::string& name, double dx, const Vec3& size, double c0, const Material& sheet) {
  Scene s;
  s.name = name;
  s.spacing = dx;
  s.gravity = Vec3(0, -9.81, 0);
  s.domain = {Vec3(-0.5, -0.5, -0.5), Vec3(size.x() + 0.5, size.y() + 0.5, size.z() + 0.5)};
  s.max_dt = 1e-3;
  s.cfl = 0.25;
  s.max_density_error = 0.05;
  s.materials = {water(c0), wall(), sheet};
  return s;
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
  const double top = y_sheet + h_up + 4 * dx;
  Scene s = tank_scene("sheet_in_shaft", dx, Vec3(w, top, w), c0, sheet);
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

// A fixed baffle (one sheet, normal +x) divides a tank 0.6 m long down to 3 dx = 0.15 m above the floor;
// its lower edge is free. Water 0.6 m deep on the left, 0.3 m on the right.
Scene sluice_scene(bool mask_density) {
  const double dx = 0.05, L = 0.3, depth = 0.2, gap = 3 * dx, H1 = 0.6, H2 = 0.3, top = 0.8;
  Scene s = tank_scene("sluice", dx, Vec3(2 * L, top, depth), 30.0, shell_sheet(1e7, 0.3, 0.05, 1000.0, 0.0));
  s.materials[0].mask_density = mask_density;
  Body baffle;
  baffle.name = "baffle";
  baffle.material = 2;
  baffle.shape.kind = ShapeKind::Rectangle;
  baffle.shape.center = Vec3(L, 0.5 * (gap + top), 0.5 * depth);
  baffle.shape.size = {top - gap, depth};
  baffle.shape.normal = Vec3::UnitX();
  baffle.shape.u_axis = Vec3::UnitY();
  baffle.shell_fixed = {Box{Vec3(-1, -1, -1), Vec3(2, 2, 2)}};
  s.bodies = {box_body("left", 0, Vec3(0, 0, 0), Vec3(L, H1, depth)),
              box_body("right", 0, Vec3(L, 0, 0), Vec3(2 * L, H2, depth)),
              container("tank", 1, Vec3(0, 0, 0), Vec3(2 * L, top, depth), {"+y"}), baffle};
  return s;
}

}  // namespace

TEST_CASE("shell-fluid: a clamped stiff sheet holds a 10 kPa difference without a leak",
          "[shell_fluid][long]") {
  // 1.02 m of water over a fixed sheet (rho g h = 10 kPa), a closed chamber of water below it. What is tested
  // is the fluid's side of the coupling: the column stands on the sheet as on a wall, and nothing of it, mass
  // or pressure, reaches the chamber.
  const double dx = 0.05, w = 0.3, y_sheet = 0.3, h_up = 1.02;
  Scene s = sheet_in_shaft(w, y_sheet, h_up, dx, shell_sheet(5e6, 0.3, 0.05, 1000.0, 20.0), 40.0);
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
  CHECK(world.shell_label_disagreements() == 0);  // a flat sheet: labels and surface agree
  CHECK(wrong_side(world, 0, false) == 0);
  CHECK(wrong_side(world, 1, true) == 0);
  CHECK(world.shell_masked_pairs() > 0);
  // The difference is what two plain walls hold, and the column feels the sheet as it feels a wall.
  CHECK(std::abs(dp / dp_walls - 1.0) < 0.02);
  CHECK(std::abs(sum_above / sum_floor - 1.0) < 0.005);
}

namespace {

// Centre deflection of a clamped square plate under a uniform load q, w = 0.00126 q a^4 / D (nu = 0.3;
// Timoshenko & Woinowsky-Krieger 1959, Theory of Plates and Shells, table 35).
double clamped_square_plate(double q, double a, double E, double t) {
  const double D = E * t * t * t / (12.0 * (1.0 - 0.09));
  return 0.00126 * q * a * a * a * a / D;
}

// Displacement along `axis` of the sheet particle nearest x (at t = 0), averaged over samples of the last
// `window` seconds up to t_end.
double settled_deflection(World& world, const Vec3& x, const Vec3& axis, double t_end, double window) {
  const Particles& P0 = world.particles();
  uint32_t id = 0;
  double best = 1e30;
  for (std::size_t i = 0; i < P0.size(); ++i)
    if (P0.kind[i] == Kind::Shell && (P0.x0[i] - x).squaredNorm() < best)
      best = (P0.x0[i] - x).squaredNorm(), id = P0.id[i];
  world.advance_to(t_end - window, [] { return true; });
  double sum = 0.0;
  const int samples = 10;
  for (int k = 1; k <= samples; ++k) {
    world.advance_to(t_end - window + window * k / samples, [] { return true; });
    const Particles& P = world.particles();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.id[i] == id && P.kind[i] == Kind::Shell) sum += (P.x[i] - P.x0[i]).dot(axis);
  }
  return sum / samples;
}

}  // namespace

// Validation-size runs (17 s and 26 s on 2 threads): hidden, run by scripts/validate_shell.sh.
TEST_CASE("shell-fluid: a water column on a clamped plate deflects it as the static load does (one side)",
          "[.shell-validation][shell_fluid]") {
  // The plate is the floor of a square shaft: 13 x 13 particles at dx = 0.025 m, the edge rows clamped
  // (span a = 0.3 m between them, a / t = 12), t = dx, E = 6.8 MPa, rho 8000 kg/m^3 (a plate wave no faster
  // than the fluid's sound), under 0.5 m of water plus its own weight.
  const double dx = 0.025, w = 13 * dx, a = 12 * dx, t = dx, E = 6.8e6, rho_s = 8000.0, H = 0.5;
  Scene s = sheet_in_shaft(w, 0.0, H, dx, shell_sheet(E, 0.3, t, rho_s, 200.0), 30.0);
  s.bodies.erase(s.bodies.begin());  // nothing below the plate
  s.bodies[1].shape.open = {"+y", "-y"};
  s.bodies[1].shape.box.min.y() = -4 * dx;
  World world(s);
  const double q = 1000.0 * 9.81 * H + rho_s * t * 9.81;
  const double w_ref = clamped_square_plate(q, a, E, t);
  // The same plate under the same load as a pressure, no fluid: the shell's own discretisation error.
  Scene dry = s;
  dry.bodies = {s.bodies[2]};
  dry.bodies[0].pressure_load = TimeSeries{{}, {-1000.0 * 9.81 * H}};
  World dry_world(dry);
  const Vec3 centre(0.5 * w, 0.0, 0.5 * w);
  const double w_dry = -settled_deflection(dry_world, centre, Vec3::UnitY(), 0.5, 0.1);
  const double w_wet = -settled_deflection(world, centre, Vec3::UnitY(), 0.5, 0.1);
  INFO("centre deflection with water " << w_wet << " m, with the load as a pressure " << w_dry
                                       << " m, clamped plate formula " << w_ref << " m; crossings "
                                       << world.shell_crossings() << ", steps " << world.steps());
  CHECK(world.shell_crossings() == 0);
  CHECK(std::abs(w_wet / w_ref - 1.0) < 0.10);
  CHECK(std::abs(w_wet / w_dry - 1.0) < 0.05);  // the fluid loads the plate as the pressure does
}

TEST_CASE("shell-fluid: a plate between two water columns deflects by the net load, nothing crosses",
          "[.shell-validation][shell_fluid]") {
  // A tank divided at x = L by one sheet, fixed everywhere but a square window (13 x 13 particles at
  // dx = 0.025 m: span a = 0.3 m between the fixed rows, a / t = 12) whose middle is elastic; water 1.0 m
  // deep on the left, 0.7 m on the right. Both sides cover the window, so the net load on it is uniform,
  // rho g (H1 - H2) = 2943 Pa, and it bulges to the right by the clamped-plate formula.
  const double dx = 0.025, L = 4 * dx, depth = 13 * dx, a = 12 * dx, t = dx, E = 4.0e6, H1 = 1.0, H2 = 0.7;
  const double y0 = 8.5 * dx, top = H1 + 4 * dx;  // fixed rows at y0 and y0 + a (on the lattice)
  Scene s =
      tank_scene("two_columns", dx, Vec3(2 * L, top, depth), 40.0, shell_sheet(E, 0.3, t, 8000.0, 200.0));
  Body sheet;
  sheet.name = "divider";
  sheet.material = 2;
  sheet.shape.kind = ShapeKind::Rectangle;
  sheet.shape.center = Vec3(L, 0.5 * top, 0.5 * depth);
  sheet.shape.size = {top, depth};  // particles at dx / 2 .. top - dx / 2 in y, dx / 2 .. depth - dx / 2 in z
  sheet.shape.normal = Vec3::UnitX();
  sheet.shape.u_axis = Vec3::UnitY();
  const double e = 0.25 * dx, big = 10.0;
  // Fixed: below and above the window, and the rows at z = dx / 2 and depth - dx / 2.
  sheet.shell_fixed = {Box{Vec3(-big, -big, -big), Vec3(big, y0 + e, big)},
                       Box{Vec3(-big, y0 + a - e, -big), Vec3(big, big, big)},
                       Box{Vec3(-big, -big, -big), Vec3(big, big, 0.5 * dx + e)},
                       Box{Vec3(-big, -big, depth - 0.5 * dx - e), Vec3(big, big, big)}};
  s.bodies = {box_body("left", 0, Vec3(0, 0, 0), Vec3(L, H1, depth)),
              box_body("right", 0, Vec3(L, 0, 0), Vec3(2 * L, H2, depth)),
              container("tank", 1, Vec3(0, 0, 0), Vec3(2 * L, top, depth), {"+y"}), sheet};
  World world(s);
  const double q = 1000.0 * 9.81 * (H1 - H2);
  const double w_ref = clamped_square_plate(q, a, E, t);
  const Vec3 centre(L, y0 + 0.5 * a, 0.5 * depth);
  const double w_wet = settled_deflection(world, centre, Vec3::UnitX(), 0.5, 0.1);
  // Sides: every left particle at x < L, every right one at x > L, up to the bulge.
  std::size_t wrong = 0;
  const Particles& P = world.particles();
  for (std::size_t i = 0; i < P.size(); ++i)
    if (P.kind[i] == Kind::Fluid &&
        (P.body[i] == 0 ? P.x[i].x() > L + 1.5 * w_ref : P.x[i].x() < L - 0.5 * dx))
      ++wrong;
  INFO("centre deflection " << w_wet << " m, net-load clamped plate formula " << w_ref << " m; crossings "
                            << world.shell_crossings() << ", particles on the wrong side " << wrong
                            << ", steps " << world.steps());
  CHECK(world.shell_crossings() == 0);
  CHECK(world.shell_label_disagreements() == 0);
  CHECK(wrong == 0);
  CHECK(std::abs(w_wet / w_ref - 1.0) < 0.10);
}

TEST_CASE("shell-fluid: 1 and 2 threads give bitwise the same run, and a checkpoint resumes bitwise",
          "[shell_fluid][checkpoint][heavy]") {
  // An elastic sheet (edge rows clamped) between a column and a closed chamber: masks, labels, imaginary
  // particles and the guard all at work.
  const Scene s = sheet_in_shaft(0.3, 0.3, 1.02, 0.05, shell_sheet(5e6, 0.3, 0.05, 1000.0, 20.0), 40.0);
  const int before = max_threads();
  uint64_t hash[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    set_threads(k + 1);
    World w(s);
    w.advance_to(0.02, [] { return true; });
    hash[k] = state_hash(w);
  }
  set_threads(before);
  CHECK(hash[0] == hash[1]);

  World a(s);
  a.advance_to(0.01, [] { return true; });
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());
  World b(s);
  b.load_state(in);
  a.advance_to(0.02, [] { return true; });
  b.advance_to(0.02, [] { return true; });
  CHECK(state_hash(a) == state_hash(b));
  CHECK(a.shell_masked_pairs() == b.shell_masked_pairs());
}

TEST_CASE("shell-fluid: water passes round a free edge, not through the sheet beside it",
          "[shell_fluid][long]") {
  // A fixed baffle (one sheet) divides a tank down to 3 dx above the floor; its lower edge is free. Water
  // 0.6 m deep on the left, 0.3 m on the right flows under the edge and the levels approach each other;
  // every particle that changes side does so below the edge.
  const double dx = 0.05, L = 0.3, gap = 3 * dx;
  World world(sluice_scene(false));
  const Particles& P = world.particles();
  auto level = [&](bool left) {
    double y = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.kind[i] == Kind::Fluid && (P.x[i].x() < L) == left) y = std::max(y, P.x[i].y());
    return y;
  };
  const double diff0 = level(true) - level(false);
  // Side of each particle by id, checked after every step.
  std::vector<int8_t> side(P.size());
  for (std::size_t i = 0; i < P.size(); ++i) side[P.id[i]] = P.x[i].x() < L ? -1 : 1;
  std::size_t passed = 0, through = 0;
  double highest = 0.0;
  world.advance_to(0.4, [&] {
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (P.kind[i] != Kind::Fluid) continue;
      const int8_t now = P.x[i].x() < L ? -1 : 1;
      if (now == side[P.id[i]]) continue;
      side[P.id[i]] = now;
      ++passed;
      highest = std::max(highest, P.x[i].y());
      if (P.x[i].y() > gap + 0.5 * dx) ++through;
    }
    return true;
  });
  const double diff = level(true) - level(false);
  INFO("level difference " << diff0 << " -> " << diff << " m; " << passed
                           << " side changes, the highest at y = " << highest << " m (edge at " << gap
                           << " m), " << through << " above the edge; crossings put back "
                           << world.shell_crossings());
  CHECK(passed > 30);
  CHECK(through == 0);
  CHECK(diff < 0.7 * diff0);
}

TEST_CASE("shell-fluid: particle shifting sees a sheet as a wall, fused and stand-alone equal",
          "[shell_fluid]") {
  // Water on both sides of a clamped sheet across a shaft, on the lattice, moving along the sheet at 0.5 m/s
  // (the shift scales with the speed). The imaginary wall particles complete the support beside the sheet
  // as a wall's layers do beside the shaft's floor: the kernel divergence of position div r (3 in the bulk,
  // under 2.5 read as a free surface, fluid/shifting.hpp) and the concentration gradient there are those
  // beside the floor. With the sheet's own particles in the sums (at their positions, with their own
  // volume) the rows beside it saw a concentration gradient across the sheet (|dC/dy| 2.26 1/m, div r 3.10).
  const double dx = 0.05, w = 0.6, y_sheet = 0.3;
  Material m = water(20.0);
  m.shifting = 2.0;
  Scene s = tank_scene("shift_sheet", dx, Vec3(w, 0.7, w), 20.0, shell_sheet(1e7, 0.3, 0.01));
  s.materials[0] = m;
  s.gravity = Vec3::Zero();
  const double top = y_sheet + 0.3;
  s.bodies = {box_body("below", 0, Vec3(0, 0, 0), Vec3(w, y_sheet, w), Vec3(0.5, 0, 0)),
              box_body("above", 0, Vec3(0, y_sheet, 0), Vec3(w, top, w), Vec3(0.5, 0, 0)),
              container("shaft", 1, Vec3(0, 0, 0), Vec3(w, 0.7, w), {"+y"}),
              clamped_sheet(2, w, y_sheet, dx)};
  World world(s);
  world.step(world.stable_dt());  // the coupling's labels and imaginary particles are built in a step
  const double dt = world.stable_dt();
  const Particles& P = world.particles();
  const NeighborSearch& nb = world.neighbors();
  const FluidContext& ctx = world.fluid_context();
  std::vector<Vec3> ref, fused;
  fluid_shifting(P, nb, ctx, dx, dt, ref);
  Particles copy = P;
  const ShiftRequest req{dx, dt, &fused};
  fluid_forces(copy, nb, ctx, &req);
  std::size_t differ = 0, moved = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    differ += fused[i] != ref[i];
    moved += ref[i].norm() > 0.0;
  }
  CHECK(moved > 0);
  CHECK(differ == 0);
  // The sums of the rows within dx of the sheet and of the floor, away from the shaft's side walls (3 dx).
  const double w_dx = ctx.kernel.W(dx);
  struct Rows {
    double div = 1e30, grad = 0.0;  // smallest div r, largest |dC/dy|
    int n = 0;
  } sheet, bottom;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    const Vec3& x = P.x[i];
    if (x.x() < 3 * dx || x.x() > w - 3 * dx || x.z() < 3 * dx || x.z() > w - 3 * dx) continue;
    Rows* rows = std::abs(x.y() - y_sheet) < dx ? &sheet : x.y() < dx ? &bottom : nullptr;
    if (!rows) continue;
    ShiftSums sums;
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = nb.index()[k];
      add_shift_neighbour(sums, P, ctx, w_dx, i, j, ctx.separation(x, P.x[j]));
    }
    rows->div = std::min(rows->div, sums.div_r);
    rows->grad = std::max(rows->grad, std::abs(sums.grad_c.y()));
    ++rows->n;
  }
  INFO(sheet.n << " particles beside the sheet: smallest div r " << sheet.div << ", largest |dC/dy| "
               << sheet.grad << " 1/m; " << bottom.n << " beside the floor: " << bottom.div << ", "
               << bottom.grad);
  REQUIRE(sheet.n == 72);  // 6 x 6 on each side
  REQUIRE(bottom.n == 36);
  CHECK(sheet.div > 2.5);  // not a free surface
  CHECK(std::abs(sheet.div - bottom.div) < 0.03 * bottom.div);
  CHECK(sheet.grad < bottom.grad + 0.5);
}

namespace {

// A clamped square sheet (10 x 10 particles at dx = 0.01 in [0, 0.1]^2, the plane y = 0; its free edge row at
// x = 0.095) and one particle of water 0.3 dx beyond that edge row, 1e-5 m above the
// sheet's plane, moving across the plane at 0.5 m/s: what the guard put back in the valve
// (docs/validation.md, "Shell aortic leaflets": blood skimming the plane of a free edge within the half
// spacing the sheet's patches reach beyond it). Returns the guard's put-backs and the particle's lowest
// height.
// The square sheet at dx = 0.01 in the plane y = 0, no gravity, clamped for x below `held_to` (x = 1: all of
// it), and room for one particle of water (material 0).
Scene free_edge_scene(const std::string& name, double held_to, Body& sheet) {
  const double dx = 0.01;
  Scene s = tank_scene(name, dx, Vec3(0.1, 0.1, 0.1), 10.0, shell_sheet(1e6, 0.3, 0.2 * dx, 1000.0));
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.2, 0.2, 0.2)};
  s.max_density_error = 0.5;  // a lone particle: its summed density is low, which is not what this is about
  sheet.name = "sheet";
  sheet.material = 2;
  sheet.shape.kind = ShapeKind::Rectangle;
  sheet.shape.center = Vec3(0.05, 0.0, 0.05);
  sheet.shape.size = {0.1, 0.1};
  sheet.shape.normal = Vec3::UnitY();
  sheet.shape.u_axis = Vec3::UnitX();
  sheet.shell_fixed = {Box{Vec3(-1, -1, -1), Vec3(held_to, 1, 1)}};
  return s;
}

std::pair<long, double> skim_free_edge(double barrier, std::vector<ShellCoupling::PutBack>* records = nullptr,
                                       uint32_t* water_id = nullptr) {
  const double dx = 0.01;
  Body sheet;
  Scene s = free_edge_scene("skim", 0.08, sheet);  // all but the last two rows held
  s.contact.shell_fluid_barrier = barrier;
  const double y = 1e-5;  // the particle's height (lattice point at the box's min + dx / 2)
  s.bodies = {sheet, box_body("water", 0, Vec3(0.093, y - 0.5 * dx, 0.045), Vec3(0.103, y + 0.5 * dx, 0.055),
                              Vec3(0, -0.5, 0))};
  World w(s);
  double lowest = 1e30;
  w.advance_to(0.01, [&] {
    for (std::size_t i = 0; i < w.particles().size(); ++i)
      if (w.particles().kind[i] == Kind::Fluid) {
        lowest = std::min(lowest, w.particles().x[i].y());
        if (water_id) *water_id = w.particles().id[i];
      }
    if (records)
      records->insert(records->end(), w.last_shell_put_backs().begin(), w.last_shell_put_backs().end());
    return true;
  });
  return {w.shell_crossings(), lowest};
}

}  // namespace

TEST_CASE("particle shifting beside boundaries: never towards one, along a corner's line, none in three",
          "[shell_fluid][fluid]") {
  // shift_from's wall rule on given sums: a concentration gradient pointing away from a floor (body 0, below
  // the particle) and a side wall (body 1, at -x), so that the unrestricted shift would go down and to the
  // left, into both. (Stop 42: first the shift's whole part normal to one summed normal was removed; at a
  // leaflet's attachment to the root's wall the part left pointed into one of them, and the part away from a
  // wall, which holds a particle that came too close off it, was lost too.)
  const double A = 2.0, h = 1.3e-3, speed = 1.0, dt = 1e-5, dx = 1e-3;
  ShiftSums s;
  s.div_r = 3.0;
  s.grad_c = Vec3(100.0, 400.0, 50.0);  // dr = -D grad C: towards -x, -y and -z
  const Vec3 free_shift = shift_from(s, A, h, speed, dt, dx);
  REQUIRE(free_shift.x() < 0.0);
  REQUIRE(free_shift.y() < 0.0);
  const double tiny = 1e-12 * free_shift.norm();
  // Beside the floor only: the shift keeps its x and z parts, loses its y part (towards the floor).
  ShiftSums floor = s;
  floor.add_boundary(0, Vec3(0.0, -80.0, 0.0));  // the floor's share of sum V grad W points down, at it
  const Vec3 f = shift_from(floor, A, h, speed, dt, dx);
  CHECK(std::abs(f.y()) < tiny);
  CHECK(f.x() == Approx(free_shift.x()));
  CHECK(f.z() == Approx(free_shift.z()));
  // A shift away from the floor is kept whole.
  ShiftSums up = floor;
  up.grad_c = -s.grad_c;
  CHECK((shift_from(up, A, h, speed, dt, dx) + free_shift).norm() < tiny);
  // In the corner of the floor and the wall, slightly tilted against each other: along the corner's line
  // only, nothing into either body.
  ShiftSums corner = floor;
  const Vec3 n_wall = Vec3(-1.0, 0.1, 0.0).normalized();
  corner.add_boundary(1, 60.0 * n_wall);
  const Vec3 c = shift_from(corner, A, h, speed, dt, dx);
  CHECK(std::abs(c.y()) < tiny);
  CHECK(std::abs(c.dot(n_wall)) < tiny);
  CHECK(c.z() == Approx(free_shift.z()));
  // (The two bodies' shares summed into one normal with its whole normal part removed, the first rule, would
  // have left 0.26 of this shift going into the floor.)
  // A third body the shift points at (at -z): no shift at all.
  ShiftSums three = corner;
  three.add_boundary(2, Vec3(0.0, 0.0, -40.0));
  CHECK(shift_from(three, A, h, speed, dt, dx).norm() < tiny);
}

TEST_CASE("shell-fluid: water close to a curved sheet is on the sheet's side of it, not a tangent plane's",
          "[shell_fluid]") {
  // A clamped cylindrical panel (radius R = 5 dx, 150 degrees, directors outward) and, midway between two
  // particles of its middle row and midway to the next row (0.71 dx from the four), water particles
  // eps = 0.01 dx off the cylinder. Outside, the nearest
  // particle's tangent plane has them inside (it leaves the cylinder by R (1 - cos(dtheta / 2)), about
  // 0.025 dx, there); inside, a flat triangle through the particles has them outside (the chord is as far
  // off). Until stop 37 the labels took the tangent plane's side, and a particle sliding along the outside
  // of a curved leaflet changed label between two steps: the guard then put it back through the sheet.
  const double dx = 0.01, R = 0.05, eps = 0.01 * dx;
  Scene s = tank_scene("curved", dx, Vec3(0.1, 0.1, 0.1), 10.0, shell_sheet(1e6, 0.3, 0.2 * dx, 1000.0));
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.1, 0.1, 0.1)};
  s.max_density_error = 0.5;  // lone particles: their summed density is low, which is not what this is about
  Body sheet;
  sheet.name = "panel";
  sheet.material = 2;
  sheet.shape.kind = ShapeKind::CylindricalPanel;
  sheet.shape.center = Vec3::Zero();
  sheet.shape.axis = Vec3::UnitZ();
  sheet.shape.radius = R;
  sheet.shape.length = 0.1;
  sheet.shape.angle = 150.0;
  sheet.shape.normal = Vec3::UnitY();
  sheet.shell_fixed = {Box{Vec3(-1, -1, -1), Vec3(1, 1, 1)}};
  s.bodies = {sheet};
  // The angles of the particles of the row nearest z = 0.
  std::vector<double> angle;
  double z_row = 1.0;
  uint16_t body = 0;
  {
    const World w(s);
    const Particles& P = w.particles();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.kind[i] == Kind::Shell && std::abs(P.x[i].z()) < std::abs(z_row)) z_row = P.x[i].z();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.kind[i] == Kind::Shell && std::abs(P.x[i].z() - z_row) < 1e-9) {
        angle.push_back(std::atan2(P.x[i].y(), P.x[i].x()));
        body = P.body[i];
      }
  }
  std::sort(angle.begin(), angle.end());
  REQUIRE(angle.size() >= 8);
  // Water midway between neighbours (away from the panel's edges), outside and inside.
  std::vector<Vec3> at;
  for (std::size_t k = 2; k + 3 < angle.size(); ++k) {
    const double mid = 0.5 * (angle[k] + angle[k + 1]);
    const double r = k % 2 ? R + eps : R - eps;  // alternately (two at one place would overlap)
    at.push_back(Vec3(r * std::cos(mid), r * std::sin(mid), z_row + 0.5 * dx));
  }
  for (std::size_t k = 0; k < at.size(); ++k)
    s.bodies.push_back(box_body("water" + std::to_string(k), 0, at[k] - Vec3::Constant(0.5 * dx),
                                at[k] + Vec3::Constant(0.5 * dx)));
  World w(s);
  w.advance_to(1e-4, [] { return true; });  // one step: its labels are those of the positions above
  const Particles& P = w.particles();
  int checked = 0, wrong = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    const double r = std::hypot(P.x[i].x(), P.x[i].y());
    const int side = w.shell_side(static_cast<uint32_t>(i), body);
    ++checked;
    if (side != (r > R ? 1 : -1)) {
      ++wrong;
      WARN("particle at r - R = " << (r - R) / dx << " dx labelled " << side);
    }
  }
  INFO(checked << " particles checked, " << wrong << " on the wrong side; crossings " << w.shell_crossings());
  CHECK(checked == static_cast<int>(at.size()));
  CHECK(wrong == 0);
  CHECK(w.shell_crossings() == 0);
}

TEST_CASE("shell-fluid: the barrier keeps water skimming a free edge's plane on its side",
          "[shell_fluid][heavy]") {
  // Beside a free edge the imaginary particles are beside the fluid particle, not under it, and a particle in
  // the sheet's plane has no pressure pushing it off: without the barrier the guard has to put it back.
  const auto [on, low_on] = skim_free_edge(1.0);
  std::vector<ShellCoupling::PutBack> records;
  uint32_t water = 0;
  const auto [off, low_off] = skim_free_edge(0.0, &records, &water);
  INFO("barrier on: " << on << " put-backs, lowest " << low_on << " m; off: " << off << " put-backs, lowest "
                      << low_off << " m");
  CHECK(off > 0);  // the case needs the barrier
  CHECK(on == 0);
  CHECK(low_on > 0.0);  // it never crossed the plane
  // Each put-back is recorded where it happened (World::last_shell_put_backs, shell_putbacks.csv of a run):
  // the water particle, found under the sheet's plane (it came from above) within the step's motion, by the
  // sheet (body 0) near its free edge row (x = 0.095; its patches reach the rim at x = 0.1).
  REQUIRE(static_cast<long>(records.size()) == off);
  for (const ShellCoupling::PutBack& r : records) {
    CHECK(r.id == water);
    CHECK(r.body == 0);
    CHECK(r.x.y() < 0.0);
    CHECK(r.depth == Approx(-r.x.y()).margin(1e-3));
    CHECK(r.depth < 0.01);
    CHECK(r.x.x() > 0.08);
    CHECK(r.x.x() < 0.11);
  }
}

TEST_CASE("shell-fluid: the barrier rounds a free edge's rim: water aimed at it keeps off it",
          "[shell_fluid]") {
  // The sheet of skim_free_edge (free edge row at x = 0.095; its patches, the guard's skirt, end at the rim
  // x = 0.1), held, and one particle of water 0.3 dx beyond the rim and 0.3 dx above the plane, moving at
  // 2.8 m/s along (-1, -1, 0): straight at the rim. Beyond the outline the barrier pushes off the rim (a
  // quarter spacing round it), as over the sheet it pushes off the face; without that, blood at a commissure
  // came round the rim within a step's motion and passed behind the skirt in the same step
  // (aortic_valve_cycle_physio.json, docs/validation.md). The particle's energy, 4e-3 J, is under the
  // barrier's K dx^2 d_c / 4 = 6e-3 J at the rim (half the kernel's patches there): it turns back 0.13 dx off
  // the rim (before the rim was rounded: 0.018 dx, and on over the sheet).
  const double dx = 0.01;
  Body sheet;
  Scene s = free_edge_scene("rim", 1.0, sheet);                // held: the rim stays at x = 0.1
  const double rim = 0.1, x0 = rim + 0.3 * dx, y0 = 0.3 * dx;  // lattice point at the box's min + dx / 2
  s.bodies = {sheet, box_body("water", 0, Vec3(x0 - 0.5 * dx, y0 - 0.5 * dx, 0.045),
                              Vec3(x0 + 0.5 * dx, y0 + 0.5 * dx, 0.055), Vec3(-2.0, -2.0, 0))};
  World w(s);
  double closest = 1e30, x_end = 0.0;
  w.advance_to(0.01, [&] {
    for (std::size_t i = 0; i < w.particles().size(); ++i)
      if (w.particles().kind[i] == Kind::Fluid) {
        const Vec3& x = w.particles().x[i];
        // Distance to the sheet's guard surface: to the rim beyond it, to the plane over it.
        const double d = x.x() >= rim ? std::hypot(x.x() - rim, x.y()) : std::abs(x.y());
        closest = std::min(closest, d);
        x_end = x.x();
      }
    return true;
  });
  INFO("closest approach to the rim " << closest / dx << " dx; x at the end " << x_end << " m; put-backs "
                                      << w.shell_crossings());
  CHECK(closest > 0.1 * dx);
  CHECK(w.shell_crossings() == 0);
}

// One water particle at rest 0.2 dx above the middle of a clamped, floppy sheet 40 times lighter than the
// fluid (inside the barrier's reach dx / 4).
static Scene light_sheet_scene(double dx, double c0) {
  Scene s = tank_scene("light", dx, Vec3(0.1, 0.1, 0.1), c0, shell_sheet(1e6, 0.3, 0.2 * dx, 125.0));
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.2, 0.2, 0.2)};
  s.contact.shell_fluid_barrier = 1.0;
  s.max_density_error = 0.5;  // a lone particle
  s.bodies = {clamped_sheet(2, 0.1, 0.0, dx), box_body("water", 0, Vec3(0.045, 0.2 * dx - 0.5 * dx, 0.045),
                                                       Vec3(0.055, 0.2 * dx + 0.5 * dx, 0.055))};
  return s;
}

TEST_CASE("shell-fluid: the barrier against a sheet 40 times lighter than the fluid stays stable",
          "[shell_fluid][heavy]") {
  // The barrier's spring on a light sheet particle is stiff: here (K = rho0 c0^2, mass per area rho0 dx / 40)
  // it throws the sheet's particles out of its reach within a fraction of the fluid's step. Held over the
  // whole step (as at stop 33) it goes on pushing them after they have left and puts energy in:
  // measured 1.1e-3 J at 4.8 ms, over the bound below (2.0e-3 J by 50 ms). Evaluated in the shells' sub-steps
  // it is a spring: 2.4e-4 J in the 10 ms run here. One water particle at rest 0.2 dx above the middle of a
  // clamped, floppy sheet (inside the barrier's reach dx / 4): the barrier pushes it off and the sheet down;
  // no more energy may come out than the barrier stored.
  const double dx = 0.01, c0 = 10.0;
  World w(light_sheet_scene(dx, c0));
  const Particles& P = w.particles();
  std::size_t fluid = 0;
  for (std::size_t i = 0; i < P.size(); ++i) fluid += P.kind[i] == Kind::Fluid ? 1 : 0;
  REQUIRE(fluid == 1);
  // The barrier's stored energy at the start bounds everything that moves later: the largest pair weight is
  // A_a A_q W2(0), and a fluid particle sees at most the patch sum of its partners (about 1 / dx^2 of area
  // weight); 2x that, for the nearest four partners.
  const double K = 1000.0 * c0 * c0, dc = 0.25 * dx, s0 = 0.2 * dx;
  const double stored = 2.0 * 0.5 * (K / dc) * dx * dx * (dc - s0) * (dc - s0);
  double most = 0.0;
  w.advance_to(0.01, [&] {
    double ke = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (P.kind[i] == Kind::Fluid) {
        ke += 0.5 * P.m[i] * P.v[i].squaredNorm();
      } else if (P.kind[i] == Kind::Shell) {  // the sheet's own mass and its sub-step velocity
        const std::size_t sl = static_cast<std::size_t>(w.shells_for_test().slot(i));
        ke += 0.5 * w.shells_for_test().mass(sl) * w.shell_velocities()[sl].squaredNorm();
      }
    }
    most = std::max(most, ke);
    return true;
  });
  INFO("largest kinetic energy " << most << " J against " << stored << " J stored; " << w.steps()
                                 << " steps, " << w.shell_substeps() << " sub-steps");
  CHECK(w.steps() > 20);
  CHECK(w.shell_substeps() > 2 * w.steps());  // the sheet is sub-cycled
  CHECK(most > 0.0);
  CHECK(most < stored);
}

TEST_CASE("shell-fluid: with the barrier at work a checkpoint resumes bitwise", "[shell_fluid][checkpoint]") {
  // The barrier reads the sheet's normals before the step's first shell update, i.e. those of the last
  // update, which lag the positions by the last sub-step's drift. The checkpoint holds that update's
  // positions and directors (Shells::restore_update); until stop 60 a resumed run recomputed the update from
  // the positions at the checkpoint, and the shell-leaflet scenes resumed with differences in the 4th digit.
  const Scene s = light_sheet_scene(0.01, 10.0);
  World a(s);
  a.advance_to(0.0002, [] { return true; });
  // Saved while the barrier still pushes the water off the sheet (within its reach dx / 4 of the sheet).
  for (std::size_t i = 0; i < a.particles().size(); ++i)
    if (a.particles().kind[i] == Kind::Fluid) CHECK(a.particles().x[i].y() < 0.25 * 0.01);
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());
  World b(s);
  b.load_state(in);
  // To 2 ms (6 ms until stop 63): the lagging normals are read in the first step after the resume, so a
  // difference shows in the state from then on.
  a.advance_to(0.002, [] { return true; });
  b.advance_to(0.002, [] { return true; });
  CHECK(state_hash(a) == state_hash(b));
}

TEST_CASE(
    "shell-fluid: blood flowing past a flap keeps the volume its density says (no shift beside a sheet)",
    "[shell_fluid][long]") {
  // A flap (a 6 x 7 mm sheet, 0.45 mm leaflet tissue, clamped along its upstream edge) in a tube of radius
  // 6 mm between a pressure inlet and outlet 500 Pa apart, with the physio scene's blood (shifting 2) at
  // c0 = 20 m/s. In 10 ms the flow reaches 0.35 m/s on average (0.6 m/s at most). Measure: the summation
  // density of the fluid, sum_j m_j W_ij, over the continuity density rho_i (eq. 12), for the particles whose
  // support holds only fluid (no wall, no sheet): 1 while the particles fill the volume that their masses and
  // densities say.
  // Until stop 50 particles beside the sheet shifted without their density changing, and the shift created
  // volume that the continuity density never saw: here 0.976, 0.977, 0.978 at 5, 7.5, 10 ms; in the physio
  // scene the blood that passed the leaflets filled 6-12 % more volume than its density said, and the
  // aorta lost 15 % of its particles in ejection (docs/validation.md, "Stop 50"). Now no particle with a
  // sheet's imaginary particles in its support shifts: 1.006, 1.014, 1.016. The checks are lower bounds:
  // thinning reads below 1, while the flap's wake stirs the particles (nearest neighbour 0.71 dx from 2.5 ms)
  // and disorder alone raises the ratio (test [fluid][diagnostics] "a shaken lattice"; docs/validation.md,
  // stop 52), so the rise above 1 is not compaction.
  const std::string scene =
      R"({"name": "flap", "domain": {"min": [-0.01, -0.008, -0.01], "max": [0.01, 0.024, 0.01]},
    "resolution": {"spacing": 0.001, "smoothing_ratio": 1.2},
    "time": {"end": 0.01, "output_interval": 0.0025},
    "gravity": [0, 0, 0],
    "materials": {"blood": {"type": "fluid", "density": 1060, "viscosity": 3.3e-06, "sound_speed": 20,
                            "background_pressure": 2000, "delta_sph": 0.1, "shifting": 2,
                            "riemann_dissipation": 3},
                  "wall": {"type": "wall"},
                  "tissue": {"type": "shell", "density": 1100, "youngs_modulus": 1.0e6, "poisson_ratio": 0.5,
                             "thickness": 0.00045, "model": "neo_hookean"}},
    "bodies": [{"name": "blood", "material": "blood",
                "shape": {"cylinder": {"base": [0, 0, 0], "axis": [0, 1, 0], "radius": 0.006,
                                       "length": 0.014}}},
               {"name": "tube", "material": "wall",
                "shape": {"tube": {"base": [0, -0.005, 0], "axis": [0, 1, 0], "radius": 0.006,
                                   "length": 0.022, "layers": 3}}},
               {"name": "flap", "material": "tissue",
                "shape": {"rectangle": {"center": [0, 0.0065, 0], "size": [0.006, 0.007], "normal": [0, 0, 1],
                                        "u_axis": [1, 0, 0]}},
                "fixed": {"min": [-0.01, 0.0029, -0.01], "max": [0.01, 0.0035, 0.01]}}],
    "open_boundaries": [{"name": "inlet", "type": "inflow", "point": [0, 0, 0], "normal": [0, 1, 0],
                         "radius": 0.006, "body": "blood", "pressure": 14500},
                        {"name": "outlet", "type": "outflow", "point": [0, 0.012, 0], "normal": [0, 1, 0],
                         "radius": 0.006, "pressure": 14000}]})";
  World world(load_scene_text(scene, {}, "flap").scene);
  const Particles& P = world.particles();
  const CubicSpline& K = world.fluid_context().kernel;
  auto number_over_density = [&] {
    const double support2 = K.support * K.support;
    double sum = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (P.kind[i] != Kind::Fluid || P.x[i].y() < 0.001 || P.x[i].y() > 0.011) continue;
      double rho = 0.0;
      bool only_fluid = true;
      for (std::size_t j = 0; j < P.size() && only_fluid; ++j) {
        const double r2 = (P.x[i] - P.x[j]).squaredNorm();
        if (r2 >= support2) continue;
        only_fluid = fluid_like(P.kind[j]);
        rho += P.m[j] * K.W(std::sqrt(r2));
      }
      if (!only_fluid) continue;
      sum += rho / P.rho[i];
      ++n;
    }
    return std::pair{sum / n, n};
  };
  const auto [start, n0] = number_over_density();
  double worst = start, mean = 0.0, speed = 0.0;
  for (const double t : {0.005, 0.0075, 0.01}) {
    world.advance_to(t, [] { return true; });
    const auto [ratio, n] = number_over_density();
    UNSCOPED_INFO("t = " << t << " s: sum m W / rho " << ratio << " over " << n << " particles");
    CHECK(n > 100);
    worst = std::min(worst, ratio);
    mean += ratio / 3.0;
  }
  for (std::size_t i = 0; i < P.size(); ++i)
    if (P.kind[i] == Kind::Fluid) speed = std::max(speed, P.v[i].norm());
  INFO("start " << start << " over " << n0 << " particles; mean " << mean << ", lowest " << worst
                << "; fastest fluid particle " << speed << " m/s; put-backs " << world.shell_crossings());
  CHECK(start == Approx(1.0).margin(0.005));  // the lattice
  CHECK(speed > 0.4);                         // the blood flows past the flap (0.63 m/s)
  CHECK(mean > 0.99);
  CHECK(worst > 0.98);
  CHECK(world.shell_crossings() == 0);
}

namespace {

// The mean, over the fluid particles whose row holds a shell particle, of their summation density (paper eq.
// 11, the shells' imaginary particles on their side included, masked pairs left out: what the continuity
// equation is the rate of) over their density, with the lists and masks of the last step.
double band_summation_ratio(const World& w) {
  const Particles& P = w.particles();
  const NeighborSearch& nb = w.neighbors();
  const FluidContext& ctx = w.fluid_context();
  const auto& idx = nb.index();
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    bool near = false;
    double s = P.m[i] * ctx.kernel.W(0.0);
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      near = near || P.kind[j] == Kind::Shell;
      s += summation_term(P, ctx, i, j, ctx.separation(P.x[i], P.x[j]));
    }
    if (!near) continue;
    sum += s / P.rho[i];
    ++n;
  }
  return n ? sum / n : 0.0;
}

}  // namespace

TEST_CASE("shell-fluid: mask_density in a short sluice run resumes bitwise from a checkpoint",
          "[shell_fluid][mask_density]") {
  // The sanitizers' case for mask_density and its checkpoint section (the long case below is [heavy]): the
  // sluice's first 28 ms, resumed from checkpoints at 20, 22, 24 and 26 ms, 2 ms on each. Without the saved
  // masks one of the four resumes differs (stop 60).
  const Scene s = sluice_scene(true);
  World a(s);
  const double t0 = 0.02;
  a.advance_to(t0, [] { return true; });
  CHECK(a.shell_masked_pairs() > 0);
  int same = 0;
  for (int m = 1; m <= 4; ++m) {
    StateWriter out;
    a.save_state(out);
    const StateReader in(out.bytes());
    World b(s);
    b.load_state(in);
    a.advance_to(t0 + 0.002 * m, [] { return true; });
    b.advance_to(t0 + 0.002 * m, [] { return true; });
    same += state_hash(a) == state_hash(b);
  }
  CHECK(same == 4);
}

TEST_CASE("shell-fluid: mask_density keeps the density on the summation density round a free edge",
          "[shell_fluid][mask_density][heavy]") {
  // The sluice above: water flows under the baffle's free edge, where the masks between the two sides change
  // from step to step. The continuity equation cannot see a neighbour appear in or vanish from a row, and
  // without mask_density the band's summation density runs ahead of its density (4.5 % in 0.28 s when this
  // test was written: the ratchet of boundary/mask_density.hpp); with it the two keep together.
  std::array<double, 2> drift{};
  for (const bool on : {false, true}) {
    Scene s = sluice_scene(on);
    s.max_density_error = 0.5;  // the summation's own jumps (below) are what is measured, not the limit
    World world(s);
    world.advance_to(0.04, [] { return true; });
    const double r0 = band_summation_ratio(world);
    double worst = 0.0, largest_error = 0.0;
    for (int k = 2; k <= 7; ++k) {
      world.advance_to(0.04 * k, [&] {
        largest_error = std::max(largest_error, world.max_density_error());
        return true;
      });
      worst = std::max(worst, std::abs(band_summation_ratio(world) - r0));
      if (!on || k != 5) continue;
      // At 0.2 s, water passing the edge (the masks change at most steps): the last step's masks are state.
      // Resumed from a checkpoint at four moments (a resume whose next step changed no mask would pass
      // without the saved masks), and from the last with 1 and 2 threads: bitwise the same.
      World a(s), t1(s), t2(s);
      const int before = max_threads();
      for (int m = 1; m <= 4; ++m) {
        StateWriter out;
        (m == 1 ? world : a).save_state(out);
        const StateReader in(out.bytes());
        if (m == 1) a.load_state(in);
        World b(s);
        b.load_state(in);
        if (m == 4) {
          t1.load_state(in);
          t2.load_state(in);
        }
        a.advance_to(0.2 + 0.002 * m, [] { return true; });
        b.advance_to(0.2 + 0.002 * m, [] { return true; });
        CHECK(state_hash(a) == state_hash(b));
      }
      set_threads(1);
      t1.advance_to(0.215, [] { return true; });
      set_threads(2);
      t2.advance_to(0.215, [] { return true; });
      set_threads(before);
      CHECK(state_hash(t1) == state_hash(t2));
    }
    INFO("mask_density " << on << ": band summation / density " << r0 << ", largest change " << worst
                         << ", largest density error " << largest_error);
    drift[on] = worst;
    CHECK(largest_error < 0.2);
  }
  CHECK(drift[0] > 0.03);  // the ratchet is there without it
  CHECK(drift[1] < 0.01);
}
