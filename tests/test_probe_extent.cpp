// The `extent` probe's "stat": "extent" (issue 20 item 4): the leading edge of the continuous fluid, not of
// the furthest droplet (sim/io/probes.cpp, docs/scenes.md).
#include <catch2/catch.hpp>

#include "builders.hpp"
#include "core/parallel.hpp"
#include "io/probes.hpp"
#include "scene_loader.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

// A 10 x 10 x 4 block of water (Δx = 0.01 m, particles at x = 0.005 .. 0.095, its edge at 0.1) and, ahead of
// it along x, a blob of 2 x 2 x 2 particles centred 6 Δx past the block's edge and one particle 16 Δx past
// it: droplets well beyond the kernel support (2h = 2.6 Δx) of the block and of each other. No gravity, no
// walls.
Scene block_and_droplets() {
  Scene s;
  s.name = "extent_test";
  s.spacing = 0.01;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.4, 0.2, 0.2)};
  s.materials = {water(10.0)};
  s.bodies = {box_body("block", 0, Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.04)),
              box_body("blob", 0, Vec3(0.15, 0.04, 0.01), Vec3(0.17, 0.06, 0.03)),
              box_body("drop", 0, Vec3(0.25, 0.05, 0.01), Vec3(0.26, 0.06, 0.02))};
  for (const char* stat : {"max", "extent"}) {
    Probe p;
    p.name = stat;
    p.type = ProbeType::Extent;
    p.bodies = {0, 1, 2};
    p.axis = 0;
    p.stat_extent = std::string(stat) == "extent";
    s.probes.push_back(p);
  }
  return s;
}

}  // namespace

TEST_CASE("extent probe: max sees the furthest droplet, extent the edge of the continuous fluid",
          "[probes][front]") {
  Scene s = block_and_droplets();
  {
    const World w(s);
    const ProbeSet probes(s, w);
    const auto v = probes.measure(w);
    REQUIRE(v.size() == 2);
    CHECK(v[0] == Approx(0.255).margin(1e-9));  // the lone droplet
    CHECK(v[1] == Approx(0.1).margin(1e-9));    // the block's edge: its last layer + dx/2
  }
  // A droplet within the link distance of the block belongs to the continuous fluid: one particle 2 Δx
  // past the block's edge (closer than 2h = 2.6 Δx) moves the edge to it; with a link of 1.5 Δx it is a
  // droplet again.
  s.bodies.push_back(box_body("near", 0, Vec3(0.11, 0.05, 0.01), Vec3(0.12, 0.06, 0.02)));
  for (Probe& p : s.probes) p.bodies = {0, 1, 2, 3};
  {
    const World w(s);
    const auto v = ProbeSet(s, w).measure(w);
    CHECK(v[0] == Approx(0.255).margin(1e-9));
    CHECK(v[1] == Approx(0.12).margin(1e-9));
  }
  s.probes[1].link = 1.5 * s.spacing;
  {
    const World w(s);
    const auto v = ProbeSet(s, w).measure(w);
    CHECK(v[1] == Approx(0.1).margin(1e-9));
  }
  // The largest cluster decides, wherever it lies: a region that keeps only the blob and the droplet
  // measures the blob (8 particles against 1), not the droplet beyond it.
  s.probes[1].link = 0.0;
  s.probes[1].region = Box{Vec3(0.13, -1, -1), Vec3(1, 1, 1)};
  {
    const World w(s);
    const auto v = ProbeSet(s, w).measure(w);
    CHECK(v[1] == Approx(0.17).margin(1e-9));
  }
}

TEST_CASE("extent probe: the continuous-fluid edge is the same for 1 and 2 threads",
          "[probes][front][determinism]") {
  // A short dam break (the determinism scene of test_fluid.cpp): max and extent of the column along x.
  Scene s = dam_break(0.05715, 0.05715 / 8, 3 * 0.05715 / 8);
  for (const char* stat : {"max", "extent"}) {
    Probe p;
    p.name = stat;
    p.type = ProbeType::Extent;
    p.bodies = {0};
    p.stat_extent = std::string(stat) == "extent";
    s.probes.push_back(p);
  }
  std::vector<double> out[2];
  for (int t = 1; t <= 2; ++t) {
    set_threads(t);
    World w(s);
    for (int k = 0; k < 60; ++k) w.step(w.stable_dt());
    out[t - 1] = ProbeSet(s, w).measure(w);
  }
  set_threads(2);
  REQUIRE(out[0].size() == 2);
  CHECK(out[0][0] == out[1][0]);
  CHECK(out[0][1] == out[1][1]);
  CHECK(out[0][1] <= out[0][0] + 0.5 * s.spacing);
  CHECK(out[0][1] > 0.05715 / 2);  // the column, not nothing
}

TEST_CASE("extent probe: the loader reads \"stat\": \"extent\" and its link", "[probes][front][scene]") {
  const auto j = nlohmann::json::parse(R"({
    "name": "t",
    "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
    "resolution": { "spacing": 0.01 },
    "time": { "end": 0.1, "output_interval": 0.01 },
    "materials": { "water": { "type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": 20 } },
    "bodies": [ { "name": "a", "material": "water", "shape": { "box": { "min": [0, 0, 0], "max": [0.1, 0.1, 0.1] } } } ],
    "probes": [ { "name": "m", "type": "extent", "bodies": ["a"], "axis": "x", "stat": "max" },
                { "name": "e", "type": "extent", "bodies": ["a"], "axis": "y", "stat": "extent" },
                { "name": "l", "type": "extent", "bodies": ["a"], "axis": "z", "stat": "extent", "link": 0.015 } ]
  })");
  const Scene s = load_scene_json(j, {}).scene;
  REQUIRE(s.probes.size() == 3);
  CHECK_FALSE(s.probes[0].stat_extent);
  CHECK(s.probes[1].stat_extent);
  CHECK(s.probes[1].stat_max);
  CHECK(s.probes[1].link == 0.0);  // the kernel support
  CHECK(s.probes[2].stat_extent);
  CHECK(s.probes[2].link == 0.015);
  // The block's edge along each axis: 0.1 m (its last particle at 0.095 m).
  const World w(s);
  const auto v = ProbeSet(s, w).measure(w);
  CHECK(v[0] == Approx(0.095).margin(1e-12));
  CHECK(v[1] == Approx(0.1).margin(1e-12));
  CHECK(v[2] == Approx(0.1).margin(1e-12));
}

TEST_CASE("max_speed probe: smoothed reads the kernel-averaged velocity and not one fast particle",
          "[probes][physiology]") {
  // A 10 x 10 x 6 block of water moving at 1 m/s along x with, inside it (a full kernel support around it),
  // one particle at 5 m/s (the single fast particle of the physio run's jet at stop 56). The block is built
  // of boxes around that particle's lattice cell [0.05, 0.06] x [0.05, 0.06] x [0.02, 0.03].
  Scene s;
  s.name = "max_speed_test";
  s.spacing = 0.01;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.4, 0.2, 0.2)};
  s.materials = {water(10.0)};
  const Vec3 U(1, 0, 0);
  s.bodies = {box_body("x_low", 0, Vec3(0, 0, 0), Vec3(0.05, 0.1, 0.06), U),
              box_body("x_high", 0, Vec3(0.06, 0, 0), Vec3(0.1, 0.1, 0.06), U),
              box_body("y_low", 0, Vec3(0.05, 0, 0), Vec3(0.06, 0.05, 0.06), U),
              box_body("y_high", 0, Vec3(0.05, 0.06, 0), Vec3(0.06, 0.1, 0.06), U),
              box_body("z_low", 0, Vec3(0.05, 0.05, 0), Vec3(0.06, 0.06, 0.02), U),
              box_body("z_high", 0, Vec3(0.05, 0.05, 0.03), Vec3(0.06, 0.06, 0.06), U),
              box_body("spike", 0, Vec3(0.05, 0.05, 0.02), Vec3(0.06, 0.06, 0.03), Vec3(5, 0, 0))};
  for (const bool smoothed : {false, true}) {
    Probe p;
    p.name = smoothed ? "smooth" : "raw";
    p.type = ProbeType::MaxSpeed;
    p.smoothed = smoothed;
    s.probes.push_back(p);
  }
  // The same two in a region that leaves the fast particle (x = 0.055) out but not its kernel support.
  for (Probe p : std::vector<Probe>(s.probes)) {
    p.name += "_region";
    p.region = Box{Vec3(-1, -1, -1), Vec3(0.05, 1, 1)};
    s.probes.push_back(p);
  }
  const World w(s);
  const auto v = ProbeSet(s, w).measure(w);
  REQUIRE(v.size() == 4);
  CHECK(v[0] == Approx(5.0).epsilon(1e-12));
  CHECK(v[2] == Approx(1.0).epsilon(1e-12));
  // The Shepard average sum_j V_j v_j W_ij / sum_j V_j W_ij over the fluid within 2h, by brute force.
  const Particles& P = w.particles();
  const CubicSpline& K = w.kernel();
  auto smoothed_speed = [&](std::size_t i) {
    Vec3 vw = Vec3::Zero();
    double sw = 0.0;
    for (std::size_t j = 0; j < P.size(); ++j) {
      const double r = (P.x[j] - P.x[i]).norm();
      if (P.kind[j] != Kind::Fluid || r >= K.support) continue;
      const double Wj = K.W(r) * P.m[j] / P.rho[j];
      vw += Wj * P.v[j];
      sw += Wj;
    }
    return (vw / sw).norm();
  };
  double all = 0.0, region = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    all = std::max(all, smoothed_speed(i));
    if (P.x[i].x() <= 0.05) region = std::max(region, smoothed_speed(i));
  }
  CHECK(v[1] == Approx(all).epsilon(1e-12));
  CHECK(v[3] == Approx(region).epsilon(1e-12));
  // The fast particle counts for its kernel share W(0) V / sum_j W_j V_j, about 2/3 alpha dx^3 = 0.145 in a
  // full support at h = 1.3 dx: 1 + 4 x 0.145 = 1.58 m/s where it sits, not 5; and inside the region its
  // neighbours outside it still count (above 1 m/s).
  CHECK(v[1] > 1.4);
  CHECK(v[1] < 1.75);
  CHECK(v[3] > 1.0 + 1e-6);
  CHECK(v[3] < v[1]);
  // A uniform flow reads its own speed.
  s.bodies.pop_back();
  const World u(s);
  const auto vu = ProbeSet(s, u).measure(u);
  CHECK(vu[0] == Approx(1.0).epsilon(1e-12));
  CHECK(vu[1] == Approx(1.0).epsilon(1e-12));
}
