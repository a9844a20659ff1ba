// The `pressure` probe with a sensor face (`radius`, `normal`; issue 20: the wall sensors of Lobovsky et al.
// 2014): the mean of the interpolated pressure over a disc, not the value at its centre (sim/io/probes.cpp).
#include <catch2/catch.hpp>
#include <cmath>

#include "builders.hpp"
#include "io/probes.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

// A 10 x 10 x 10 block of water, Δx = 0.01 m, no gravity, no walls; probes on its -x face at mid height: a
// point probe, a sensor of radius R facing +x, and a sensor 0.1 m above the block (dry).
constexpr double kR = 0.02, kYc = 0.05;

Scene block_with_sensors() {
  Scene s;
  s.name = "pressure_sensor_test";
  s.spacing = 0.01;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.1, -0.1, -0.1), Vec3(0.2, 0.3, 0.2)};
  s.materials = {water(10.0)};
  s.bodies = {box_body("block", 0, Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1))};
  for (int k = 0; k < 3; ++k) {
    Probe p;
    p.name = "p" + std::to_string(k);
    p.type = ProbeType::Pressure;
    p.point = Vec3(0.0, k == 2 ? 0.2 : kYc, 0.05);
    if (k > 0) {
      p.radius = kR;
      p.normal = Vec3::UnitX();
    }
    s.probes.push_back(p);
  }
  return s;
}

// The probes' readings with the block's pressure set to f(y) (the probe reads the particles' p as it is).
template <class F>
std::vector<double> readings(F f) {
  const Scene s = block_with_sensors();
  World w(s);
  ProbeSet probes(s, w);
  Particles& P = const_cast<Particles&>(w.particles());  // a prescribed field, to test the probe alone
  for (std::size_t i = 0; i < P.size(); ++i) P.p[i] = f(P.x[i].y());
  return probes.measure(w);
}

}  // namespace

TEST_CASE("pressure sensor: a linear field reads its centre value, a dry sensor reads 0",
          "[probe][pressure]") {
  const auto v = readings([](double y) { return 1000.0 + 5000.0 * y; });
  INFO("point " << v[0] << " Pa, sensor " << v[1] << " Pa, dry sensor " << v[2] << " Pa");
  CHECK(v[0] == Approx(1000.0 + 5000.0 * kYc).epsilon(0.005));
  CHECK(v[1] == Approx(v[0]).epsilon(0.005));  // the disc's mean of a linear field is its centre's value
  CHECK(v[2] == 0.0);                          // no fluid within R + 2h: air
}

TEST_CASE("pressure sensor: it averages over its face (a quadratic field reads more than at the centre)",
          "[probe][pressure]") {
  // p = C (y - yc)^2: the 29-point grid of pitch R/3 adds C (R/3)^2 * 68/29 (sum of j^2 over the grid
  // points, per point) to the centre's value; the kernel's own smoothing adds the same at every point.
  const double C = 1e6;
  const auto v = readings([&](double y) { return C * (y - kYc) * (y - kYc); });
  const double expected = C * (kR / 3) * (kR / 3) * 68.0 / 29.0;
  INFO("point " << v[0] << " Pa, sensor " << v[1] << " Pa, expected difference " << expected << " Pa");
  CHECK(v[1] - v[0] == Approx(expected).epsilon(0.05));
}
