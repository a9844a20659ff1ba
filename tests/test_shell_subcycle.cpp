// Shell sub-cycling within the step (World::step_shells, issue 16 item 2): a shell scene stepped with a large
// step (many shell sub-steps per World step) follows the run whose World step is the shell's own (one
// sub-step each).
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "builders.hpp"
#include "world.hpp"

using namespace aortasph;
using aortasph::test::shell_sheet;

namespace {

// A cantilever strip along x: free length L, width 3 dx, clamped by three fixed rows at x < 0.
Scene strip(double L, double t, double dx, double E, double rho, double max_dt) {
  Scene s;
  s.name = "strip";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-2 * L, -2 * L, -2 * L), Vec3(2 * L, 2 * L, 2 * L)};
  s.max_dt = max_dt;
  s.cfl = 0.5;
  s.materials = {shell_sheet(E, 0.0, t, rho)};
  Body b;
  b.name = "strip";
  b.material = 0;
  b.shape.kind = ShapeKind::Rectangle;
  b.shape.center = Vec3(0.5 * (L - 3 * dx), 0, 0);
  b.shape.size = {L + 3 * dx, 3 * dx};
  b.shape.normal = Vec3::UnitZ();
  b.shape.u_axis = Vec3::UnitX();
  b.shell_fixed = {Box{Vec3(-1, -1, -1), Vec3(0, 1, 1)}};
  s.bodies = {b};
  return s;
}

}  // namespace

TEST_CASE("shell sub-cycling: a large step gives the run of the shell's own step",
          "[shell][subcycle][long]") {
  const double L = 1.0, t = 0.1, dx = L / 20, E = 1e7, rho = 1000.0;
  const double f1 = 1.8751 * 1.8751 / (2 * std::numbers::pi * L * L) * std::sqrt(E * t * t / (12 * rho));
  const double T = 1.0 / f1, v0 = 1e-3 * L * 2 * std::numbers::pi * f1;
  double dt_shell = 0.0;
  {
    World probe(strip(L, t, dx, E, rho, 1.0));
    dt_shell = probe.shell_stable_dt();
  }
  std::vector<double> tip_z[2];
  long steps[2] = {0, 0}, sub[2] = {0, 0};
  for (int run = 0; run < 2; ++run) {
    // run 0: World steps of T / 40 (tens of sub-steps each); run 1: max_dt under the shell's step (n = 1).
    World w(strip(L, t, dx, E, rho, run == 0 ? 1.0 : 0.9 * dt_shell));
    w.set_initial_velocity(0, [&](const Vec3& x0) {
      const double z = x0.x() / L;
      return Vec3(0, 0, x0.x() > 0 ? v0 * z * z : 0.0);
    });
    std::size_t tip = 0;
    for (std::size_t i = 0; i < w.particles().size(); ++i)
      if (w.particles().x0[i].x() > w.particles().x0[tip].x()) tip = i;
    for (int k = 1; k <= 40; ++k) {
      w.advance_to(k * T / 40, [] { return true; });
      tip_z[run].push_back(w.particles().x[tip].z());
    }
    steps[run] = w.steps();
    sub[run] = w.shell_substeps();
    if (run == 0) CHECK(w.last_shell_substeps() > 10);
    if (run == 1) CHECK(w.last_shell_substeps() == 1);
  }
  double amp = 0.0, diff = 0.0;
  for (std::size_t k = 0; k < tip_z[0].size(); ++k) {
    amp = std::max(amp, std::abs(tip_z[1][k]));
    diff = std::max(diff, std::abs(tip_z[0][k] - tip_z[1][k]));
  }
  WARN("sub-cycled: " << steps[0] << " steps, " << sub[0] << " shell sub-steps; un-sub-cycled: " << steps[1]
                      << " steps; tip amplitude " << amp << ", largest difference " << diff << " ("
                      << diff / amp << " of it)");
  // Both are leapfrogs of the same equations with sub-steps within 10 % of each other; the leapfrog's phase
  // error per period is (omega h)^2 / 24 ~ 1e-8 here, so a difference of 1e-3 of the amplitude would be a
  // coupling error (a mistimed first kick alone, h / 2, shifts the phase by pi h / T ~ 1e-3).
  CHECK(amp > 0.0);
  CHECK(diff < 1e-4 * amp);
  CHECK(steps[0] * 10 < steps[1]);
}
