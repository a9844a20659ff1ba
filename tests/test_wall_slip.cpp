// Free-slip walls for the viscous term (issue 20 item 3; body "slip": "free_slip", fluid/fluid_wcsph.cpp):
// a channel driven by a body force between two plates. With no-slip plates (Adami et al. 2012, eq. 22) the
// start-up profile is curved and the wall shear takes momentum out; with free-slip plates nothing resists
// the force along the plates, so the fluid moves as a plug and gains exactly the momentum the force gives.
#include <catch2/catch.hpp>
#include <cmath>

#include "builders.hpp"
#include "scene_loader.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

// Plates at y = 0 and y = L (3 wall layers each), periodic in x and z (8 spacings each), water-like fluid at
// rest driven by F along x (the Poiseuille case of test_periodic.cpp: u_max = F L^2 / (8 nu) = 1 mm/s).
Scene channel(bool free_slip) {
  const double L = 1e-3, nu = 1e-6, F = 8e-3, dx = L / 10, w = 8 * dx;
  Scene s;
  s.name = "slip_channel";
  s.spacing = dx;
  s.gravity = Vec3(F, 0, 0);
  s.domain = {Vec3(0, -4 * dx, 0), Vec3(w, L + 4 * dx, w)};
  s.periodic = {true, false, true};
  s.t_end = 1.0;
  s.max_dt = 1e-3;
  Material m = water(0.02);
  m.viscosity = nu;
  s.materials = {m, wall()};
  s.bodies = {box_body("fluid", 0, Vec3(0, 0, 0), Vec3(w, L, w)),
              box_body("floor", 1, Vec3(0, -3 * dx, 0), Vec3(w, 0, w)),
              box_body("lid", 1, Vec3(0, L, 0), Vec3(w, L + 3 * dx, w))};
  s.bodies[1].free_slip = s.bodies[2].free_slip = free_slip;
  return s;
}

struct ChannelProfile {
  double mean = 0, wall = 0, centre = 0, min = 1e30, max = -1e30;  // u_x: mean, first layer, middle layers
};

ChannelProfile profile(const World& w) {
  const Particles& P = w.particles();
  const double dx = w.scene().spacing, L = 10 * dx;
  ChannelProfile r;
  double n = 0, nw = 0, nc = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Fluid) continue;
    const double u = P.v[i].x(), y = P.x[i].y();
    r.mean += u, n += 1;
    r.min = std::min(r.min, u), r.max = std::max(r.max, u);
    if (y < dx || y > L - dx) r.wall += u, nw += 1;
    if (std::abs(y - 0.5 * L) < dx) r.centre += u, nc += 1;
  }
  r.mean /= n, r.wall /= nw, r.centre /= nc;
  return r;
}

}  // namespace

TEST_CASE("free-slip plates: a force-driven channel moves as a plug, no-slip plates give a curved profile",
          "[wall-slip][fluid]") {
  const double F = 8e-3, t = 0.2;  // 0.2 s: twice the slowest viscous time L^2 / (pi^2 nu)
  const double plug = F * t;       // the free fluid's velocity: 1.6 mm/s
  World ws(channel(true));
  ws.advance_to(t, [] { return true; });
  const ChannelProfile fs = profile(ws);
  INFO("free slip: mean " << fs.mean / plug << ", wall layer " << fs.wall / plug << ", centre "
                          << fs.centre / plug << ", min " << fs.min / plug << ", max " << fs.max / plug
                          << " (of F t)");
  // Nothing takes momentum out along x: the mean velocity is F t (pressure forces of the plates have no
  // mean x component), and every particle moves with it.
  CHECK(std::abs(fs.mean / plug - 1.0) < 0.01);
  CHECK(fs.min / plug > 0.98);
  CHECK(fs.max / plug < 1.02);

  World wn(channel(false));
  wn.advance_to(t, [] { return true; });
  const ChannelProfile ns = profile(wn);
  INFO("no slip: mean " << ns.mean / plug << ", wall layer " << ns.wall / plug << ", centre "
                        << ns.centre / plug << " (of F t)");
  // The start-up Poiseuille profile: near 0.86 u_max = 0.54 F t at the centre (the series solution at
  // nu t / L^2 = 0.2), slow next to the plates, and the mean far below F t.
  CHECK(ns.mean / plug < 0.5);
  CHECK(ns.centre / ns.wall > 2.0);
}

TEST_CASE("the loader reads a body's slip condition, no slip by default", "[wall-slip][scene]") {
  const auto j = nlohmann::json::parse(R"({
    "name": "t",
    "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
    "resolution": { "spacing": 0.01 },
    "time": { "end": 0.1, "output_interval": 0.01 },
    "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 20 },
                   "wall": { "type": "wall" } },
    "bodies": [ { "name": "a", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.1, 0.1, 0.1] } } },
                { "name": "floor", "material": "wall", "slip": "free_slip",
                  "shape": { "box": { "min": [0, -0.03, 0], "max": [0.1, 0, 0.1] } } },
                { "name": "side", "material": "wall", "slip": "no_slip",
                  "shape": { "box": { "min": [-0.03, 0, 0], "max": [0, 0.1, 0.1] } } },
                { "name": "back", "material": "wall",
                  "shape": { "box": { "min": [0.1, 0, 0], "max": [0.13, 0.1, 0.1] } } } ]
  })");
  const Scene s = load_scene_json(j, {}).scene;
  REQUIRE(s.bodies.size() == 4);
  CHECK(s.bodies[1].free_slip);
  CHECK_FALSE(s.bodies[2].free_slip);
  CHECK_FALSE(s.bodies[3].free_slip);
}
