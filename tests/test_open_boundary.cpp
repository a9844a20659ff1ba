// Open boundaries (sim/open_boundary.hpp) and the flow probes: a straight tube with an inflow at the bottom
// and an outflow at the top, no gravity, blood.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "errors.hpp"
#include "parallel.hpp"
#include "probes.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

using namespace aortasph;

namespace {

struct TubeSetup {
  double dx = 1e-3;
  int radius_dx = 4;   // tube radius in spacings
  int length_dx = 16;  // fluid between the inlet and the outlet disc, in spacings
  int layers = 4;
  double c0 = 1.0;  // 10 x the inflow speed: Mach 0.1
  double initial_velocity = 0.0;
  TimeSeries velocity{{}, {0.1}};
  bool parabolic = false;
  TimeSeries pressure{{}, {0.0}};
};

Material blood(double c0) {
  Material m;
  m.name = "blood";
  m.type = MaterialType::Fluid;
  m.density = 1060.0;
  m.viscosity = 3.3e-6;  // 3.5 mPa s / 1060 kg/m^3
  m.sound_speed = c0;
  return m;
}

// Axis +y. Inlet disc at y = 0 (its buffer below), outlet disc at y = L (its buffer above, filled at the
// start by the fluid column, which runs through it). The tube wall covers both buffers and one spacing more.
Scene tube_scene(const TubeSetup& t) {
  const double dx = t.dx, R = t.radius_dx * dx, L = t.length_dx * dx, D = t.layers * dx;
  Scene s;
  s.name = "tube_flow";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-R - 6 * dx, -D - 4 * dx, -R - 6 * dx), Vec3(R + 6 * dx, L + D + 4 * dx, R + 6 * dx)};
  s.t_end = 1.0;
  s.max_dt = 1e-3;
  Material wall;
  wall.name = "wall";
  wall.type = MaterialType::Wall;
  s.materials = {blood(t.c0), wall};
  Body fluid;
  fluid.name = "blood";
  fluid.material = 0;
  fluid.shape.kind = ShapeKind::Cylinder;
  fluid.shape.base = Vec3::Zero();
  fluid.shape.axis = Vec3::UnitY();
  fluid.shape.radius = R;
  fluid.shape.length = L + D;
  fluid.velocity = Vec3(0, t.initial_velocity, 0);
  Body tube;
  tube.name = "tube";
  tube.material = 1;
  tube.shape.kind = ShapeKind::Tube;
  tube.shape.base = Vec3(0, -D - dx, 0);
  tube.shape.axis = Vec3::UnitY();
  tube.shape.radius = R;
  tube.shape.length = L + 2 * D + 2 * dx;
  tube.shape.layers = 3;
  s.bodies = {fluid, tube};

  OpenBoundarySpec in;
  in.name = "inlet";
  in.type = OpenBoundaryType::Inflow;
  in.point = Vec3::Zero();
  in.normal = Vec3::UnitY();
  in.radius = R;
  in.layers = t.layers;
  in.body = 0;
  in.velocity = t.velocity;
  in.parabolic = t.parabolic;
  OpenBoundarySpec out;
  out.name = "outlet";
  out.type = OpenBoundaryType::Outflow;
  out.point = Vec3(0, L, 0);
  out.normal = Vec3::UnitY();
  out.radius = R;
  out.layers = t.layers;
  out.pressure = t.pressure;
  s.open_boundaries = {in, out};

  Probe q;
  q.name = "q_mid";
  q.type = ProbeType::FlowRate;
  q.point = Vec3(0, 0.5 * L, 0);
  q.normal = Vec3::UnitY();
  q.radius = R;
  Probe bal;
  bal.name = "bal";
  bal.type = ProbeType::OpenBoundary;
  Probe p_out;
  p_out.name = "p_out";
  p_out.type = ProbeType::Pressure;
  p_out.point = Vec3(0, L - 3 * dx, 0);
  s.probes = {q, bal, p_out};
  return s;
}

struct Row {
  double t, q_mid, volume_in, volume_out, volume_inside, prescribed, p_out;
};

// Runs the scene to t_end, one probe row every `every` seconds.
std::vector<Row> run(const Scene& s, double t_end, double every) {
  World w(s);
  ProbeSet probes(s, w);
  std::vector<Row> rows;
  auto sample = [&] {
    const auto v = probes.measure(w);
    rows.push_back({w.time(), v[0], v[1], v[2], v[3], v[4], v[5]});
  };
  sample();
  for (double t = every; t <= t_end + 1e-12; t += every) {
    w.advance_to(t, [] { return true; });
    sample();
  }
  if (std::getenv("OB_DEBUG")) {
    for (const auto& [name, sec] : w.profile().phases()) printf("%s %.3f\n", name.c_str(), sec);
    printf("steps %ld builds %ld n %zu\n", w.steps(), w.list_builds(), w.particles().size());
    for (const Row& r : rows)
      printf("%.3f q %.4e vin %.4e vout %.4e vins %.4e pres %.4e p %.3f\n", r.t, r.q_mid, r.volume_in,
             r.volume_out, r.volume_inside, r.prescribed, r.p_out);
  }
  return rows;
}

double mean(const std::vector<Row>& rows, double t0, double t1, double Row::*field) {
  double s = 0.0;
  int n = 0;
  for (const Row& r : rows)
    if (r.t >= t0 - 1e-12 && r.t <= t1 + 1e-12) {
      s += r.*field;
      ++n;
    }
  return n ? s / n : NAN;
}

}  // namespace

TEST_CASE("tube flow: the mid-tube flow rate matches the prescribed inflow", "[open]") {
  TubeSetup t;
  t.initial_velocity = 0.1;  // the paper's set-up: the column already moves, the inflow keeps it going
  const Scene s = tube_scene(t);
  const double t_end = 0.1;
  const auto rows = run(s, t_end, 0.0025);
  const double prescribed = rows.back().prescribed;
  // 52 columns of dx^2 at 0.1 m/s.
  CHECK(prescribed == Approx(0.1 * 52 * t.dx * t.dx).epsilon(1e-12));
  const double q = mean(rows, 0.04, t_end, &Row::q_mid);
  INFO("mean mid-tube flow " << q << " m^3/s, prescribed " << prescribed);
  CHECK(std::abs(q / prescribed - 1.0) < 0.03);
  // The fluid that came in went somewhere: volume in - out = change inside (weak compressibility only).
  const Row& a = rows.front();
  const Row& b = rows.back();
  const double in = b.volume_in - a.volume_in, out = b.volume_out - a.volume_out;
  const double change = b.volume_inside - a.volume_inside;
  INFO("in " << in << " out " << out << " change inside " << change);
  CHECK(in > 0.5 * prescribed * t_end);  // the test measures something
  CHECK(std::abs(in - out - change) < 0.01 * in);
  // The inflow delivers the prescribed volume: within one layer of particles of the inlet.
  CHECK(std::abs(in - prescribed * t_end) < 52 * t.dx * t.dx * t.dx);
}
