// Physiological boundary conditions (issue 17): the pressure inlet and the RCR Windkessel outlet
// (sim/boundary/open_boundary.hpp, sim/physiology/windkessel.hpp, sim/physiology/waveform.hpp), their scene
// keys and waveform files (app/scene_loader.cpp, app/waveform_csv.hpp), the open_boundary probe's flow and
// pressure columns, checkpoints and determinism.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cctype>
#include <cmath>
#include <complex>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <thread>

#include "builders.hpp"
#include "cli_helpers.hpp"
#include "core/parallel.hpp"
#include "errors.hpp"
#include "io/checkpoint.hpp"
#include "io/probes.hpp"
#include "physiology/waveform.hpp"
#include "physiology/windkessel.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

using namespace aortasph;
using aortasph::test::state_hash;
namespace fs = std::filesystem;

namespace {

constexpr double kMmHg = 133.322387415;  // Pa
constexpr double kMl = 1e-6;             // m^3

// The normal systemic set shipped in docs/scenes.md (Stergiopulos et al. 1999 / Westerhof et al. 2009).
WindkesselParams systemic() {
  WindkesselParams w;
  w.proximal_resistance = 0.05 * kMmHg / kMl;
  w.capacitance = 1.6 * kMl / kMmHg;
  w.distal_resistance = 1.05 * kMmHg / kMl;
  w.distal_pressure = 0.0;
  w.initial_pressure = 80.0 * kMmHg;
  return w;
}

// A scene file's JSON: a straight tube (axis +y, radius 4 mm) with a pressure inlet at y = 0 and a Windkessel
// outlet at y = 16 mm; each bad-input case below breaks one thing.
nlohmann::json tube_json() {
  return nlohmann::json::parse(R"({
    "name": "tube",
    "domain": { "min": [-0.01, -0.01, -0.01], "max": [0.01, 0.03, 0.01] },
    "resolution": { "spacing": 0.001 },
    "time": { "end": 0.004, "output_interval": 0.002 },
    "gravity": [0, 0, 0],
    "materials": { "blood": { "type": "fluid", "density": 1060, "viscosity": 1e-3, "sound_speed": 2,
                              "background_pressure": 100 },
                   "wall": { "type": "wall" } },
    "bodies": [ { "name": "blood", "material": "blood",
                  "shape": { "cylinder": { "base": [0, 0, 0], "axis": [0, 1, 0], "radius": 0.004, "length": 0.02 } } },
                { "name": "tube", "material": "wall",
                  "shape": { "tube": { "base": [0, -0.005, 0], "axis": [0, 1, 0], "radius": 0.004, "length": 0.03 } } } ],
    "open_boundaries": [
      { "name": "lv", "type": "inflow", "point": [0, 0, 0], "normal": [0, 1, 0], "radius": 0.004,
        "body": "blood", "pressure": [[0, 100], [0.002, 140]] },
      { "name": "aorta", "type": "outflow", "point": [0, 0.016, 0], "normal": [0, 1, 0], "radius": 0.004,
        "windkessel": { "proximal_resistance": 5e5, "capacitance": 6e-9, "distal_resistance": 3e6,
                        "distal_pressure": 100, "initial_pressure": 100 } } ],
    "probes": [ { "name": "bal", "type": "open_boundary" } ]
  })");
}

}  // namespace

TEST_CASE("windkessel: a constant flow charges C to P_d + Q (R_p + R_d) with time constant R_d C",
          "[physiology]") {
  const WindkesselParams w = systemic();
  const double Q = 100.0 * kMl;  // 100 ml/s
  const double tau = w.distal_resistance * w.capacitance;
  REQUIRE(tau == Approx(1.68));
  auto analytic = [&](double t) {
    const double p_inf = w.distal_pressure + Q * w.distal_resistance;
    return p_inf + (w.initial_pressure - p_inf) * std::exp(-t / tau) + w.proximal_resistance * Q;
  };
  // A fluid-like step (1e-4 s) and steps of 0.5, 2 and 10 time constants (stability: no overshoot, no
  // oscillation, the same curve at the step ends).
  for (const double dt : {1e-4, 0.5 * tau, 2.0 * tau, 10.0 * tau}) {
    WindkesselState s = windkessel_start(w, Q);
    CHECK(s.p_out == Approx(w.initial_pressure + w.proximal_resistance * Q));
    double t = 0.0, worst = 0.0, prev = s.p_out;
    const double t_end = 20.0 * tau;
    while (t < t_end - 1e-12) {
      windkessel_step(w, s, Q, dt);
      t += dt;
      worst = std::max(worst, std::abs(s.p_out / analytic(t) - 1.0));
      CHECK(s.p_out >= prev - 1e-9);  // the charging curve rises monotonically
      prev = s.p_out;
    }
    INFO("dt " << dt << " s: worst relative error " << worst);
    CHECK(worst < 0.01);
    CHECK(s.p_out ==
          Approx(w.distal_pressure + Q * (w.proximal_resistance + w.distal_resistance)).epsilon(1e-6));
    // Time constant: at t = tau the capacitor has gone 1 - 1/e of the way.
    WindkesselState a = windkessel_start(w, Q);
    windkessel_step(w, a, Q, tau);
    const double p_inf = w.distal_pressure + Q * w.distal_resistance;
    CHECK((a.pc - w.initial_pressure) / (p_inf - w.initial_pressure) ==
          Approx(1.0 - std::exp(-1.0)).epsilon(1e-9));
  }
}

TEST_CASE("windkessel: a pulsatile flow against the analytic solution, also at a coarse step",
          "[physiology]") {
  // Q(t) = Q0 + Q1 sin(w t): u = P_c - P_d solves tau u' = R_d Q - u, u(t) = R_d Q0 + Q1 R_d Im(e^{iwt} /
  // (1 + i w tau)) + (u(0) - u_p(0)) e^{-t/tau}; P_out = P_c + R_p Q.
  const WindkesselParams w = systemic();
  const double tau = w.distal_resistance * w.capacitance;
  const double Q0 = 80.0 * kMl, Q1 = 200.0 * kMl, om = 2.0 * M_PI / 0.8;
  auto Q = [&](double t) { return Q0 + Q1 * std::sin(om * t); };
  auto up = [&](double t) {
    return w.distal_resistance * Q0 +
           Q1 * w.distal_resistance *
               (std::exp(std::complex<double>(0.0, om * t)) / std::complex<double>(1.0, om * tau)).imag();
  };
  const double u0 = w.initial_pressure - w.distal_pressure;
  auto exact = [&](double t) {
    return w.distal_pressure + up(t) + (u0 - up(0.0)) * std::exp(-t / tau) + w.proximal_resistance * Q(t);
  };
  for (const double dt : {1e-4, 0.02}) {
    WindkesselState s = windkessel_start(w, Q(0.0));
    double worst = 0.0, t = 0.0;
    const int n = static_cast<int>(std::lround(4.0 / dt));
    for (int k = 1; k <= n; ++k) {
      t = k * dt;
      windkessel_step(w, s, Q(t), dt);
      worst = std::max(worst, std::abs(s.p_out - exact(t)));
    }
    INFO("dt " << dt << ": worst error " << worst / kMmHg << " mmHg");
    // Within 1 % of the pressure's swing (R_p Q1 + |Z| Q1 is about 40 mmHg).
    CHECK(worst < 0.01 * 40.0 * kMmHg);
  }
}

TEST_CASE("waveform: tables repeat with their period, files load in mmHg with an offset", "[physiology]") {
  Waveform w;
  w.t = {0.0, 0.2, 0.6};
  w.value = {0.0, 10.0, 2.0};
  w.period = 0.8;
  w.offset = 100.0;
  CHECK(w.at(0.1) == Approx(105.0));
  CHECK(w.at(0.9) == Approx(105.0));   // one period later
  CHECK(w.at(-0.7) == Approx(105.0));  // and before
  CHECK(w.at(0.7) == Approx(101.0));   // between the last point and the next cycle's first: closed linearly
  w.period = 0.0;
  CHECK(w.at(0.7) == Approx(102.0));  // not repeated: held
  // The shipped left-ventricular waveform: 75 bpm, about 120/8 mmHg, ejection about 0.3 s; read through the
  // loader (mmHg, period, offset) as a pressure inlet's.
  const fs::path file = fs::path(AORTASPH_TEST_DIR) / ".." / "scenes" / "waveforms" / "lv_pressure.csv";
  std::ifstream f(file);
  std::string first;
  std::getline(f, first);
  CHECK(first.rfind("# source:", 0) == 0);
  nlohmann::json j = tube_json();
  j["open_boundaries"][0]["pressure"] = {
      {"file", fs::absolute(file).string()}, {"units", "mmHg"}, {"period", 0.8}, {"offset", 50.0}};
  const Scene sc = load_scene_json(j, {}).scene;
  REQUIRE(sc.open_boundaries[0].pressure_inlet);
  const Waveform& lv = sc.open_boundaries[0].inlet_pressure;
  double pmax = -1e300, pmin = 1e300, above = 0.0;
  const int n = 8000;
  for (int k = 0; k < n; ++k) {
    const double t = 0.8 * k / n, p = (lv.at(t) - 50.0) / kMmHg;
    pmax = std::max(pmax, p);
    pmin = std::min(pmin, p);
    if (p > 80.0) above += 0.8 / n;  // above a normal diastolic aortic pressure: the ejection phase
    CHECK(lv.at(t + 0.8) == Approx(lv.at(t)));
  }
  INFO("LV pressure " << pmax << " / " << pmin << " mmHg, above 80 mmHg for " << above << " s");
  CHECK(pmax > 110.0);
  CHECK(pmax < 130.0);
  CHECK(pmin > 2.0);
  CHECK(pmin < 12.0);
  CHECK(above > 0.22);
  CHECK(above < 0.36);
}

namespace {

// A straight tube along +y, as tests/test_open_boundary.cpp's: an inflow disc at y = 0 (buffer below), an
// outflow disc at y = L (buffer above, filled by the fluid column at the start); no gravity. The inlet is a
// pressure inlet unless `velocity` is set; the outlet a constant pressure unless `windkessel` is set.
struct PTube {
  double dx = 1e-3;
  int radius_dx = 4;
  int length_dx = 16;
  int layers = 4;
  double c0 = 2.0;
  double nu = 1e-3;           // kinematic viscosity [m^2/s]: a slow, laminar, quickly developed flow
  double background = 100.0;  // [Pa]
  double initial_velocity = 0.0;
  double shifting = 0.0;  // the blood's particle-shifting coefficient
  Waveform inlet{{}, {100.0}, 0.0, 0.0};
  std::optional<double> velocity;  // a velocity inlet instead
  double outlet = 100.0;
  std::optional<WindkesselParams> windkessel;
  double output_interval = 0.002;
};

Scene ptube(const PTube& t) {
  const double dx = t.dx, R = t.radius_dx * dx, L = t.length_dx * dx, D = t.layers * dx;
  Scene s;
  s.name = "ptube";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-R - 6 * dx, -D - 4 * dx, -R - 6 * dx), Vec3(R + 6 * dx, L + D + 4 * dx, R + 6 * dx)};
  s.t_end = 1.0;
  s.output_interval = t.output_interval;
  s.max_dt = 1e-3;
  Material blood;
  blood.name = "blood";
  blood.type = MaterialType::Fluid;
  blood.density = 1060.0;
  blood.viscosity = t.nu;
  blood.sound_speed = t.c0;
  blood.background_pressure = t.background;
  blood.shifting = t.shifting;
  Material wall;
  wall.name = "wall";
  wall.type = MaterialType::Wall;
  s.materials = {blood, wall};
  Body fluid;
  fluid.name = "blood";
  fluid.material = 0;
  fluid.shape.kind = ShapeKind::Cylinder;
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
  in.normal = Vec3::UnitY();
  in.radius = R;
  in.layers = t.layers;
  in.body = 0;
  if (t.velocity) {
    in.velocity = TimeSeries{{}, {*t.velocity}};
  } else {
    in.pressure_inlet = true;
    in.inlet_pressure = t.inlet;
  }
  OpenBoundarySpec out;
  out.name = "outlet";
  out.type = OpenBoundaryType::Outflow;
  out.point = Vec3(0, L, 0);
  out.normal = Vec3::UnitY();
  out.radius = R;
  out.layers = t.layers;
  out.pressure = TimeSeries{{}, {t.outlet}};
  out.windkessel = t.windkessel;
  s.open_boundaries = {in, out};
  Probe q;
  q.name = "q_mid";
  q.type = ProbeType::FlowRate;
  q.point = Vec3(0, 0.5 * L, 0);
  q.normal = Vec3::UnitY();
  q.radius = R;
  Probe p1;
  p1.name = "p1";
  p1.type = ProbeType::Pressure;
  p1.point = Vec3(0, 0.25 * L, 0);
  Probe p2 = p1;
  p2.name = "p2";
  p2.point = Vec3(0, 0.75 * L, 0);
  Probe bal;
  bal.name = "bal";
  bal.type = ProbeType::OpenBoundary;
  s.probes = {q, p1, p2, bal};
  return s;
}

// Probe rows by column name, one per output interval.
struct Rows {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;  // time first
  std::vector<std::size_t> outflow;       // the outflow buffers' particles at each row
  double mean(const std::string& name, double t0, double t1) const {
    const std::size_t c = std::find(columns.begin(), columns.end(), name) - columns.begin() + 1;
    REQUIRE(c <= columns.size());
    double sum = 0.0;
    int n = 0;
    for (const auto& r : rows)
      if (r[0] > t0 - 1e-12 && r[0] < t1 + 1e-12) sum += r[c], ++n;
    return n ? sum / n : NAN;
  }
};

Rows run(const Scene& s, double t_end, const std::function<void(const World&)>& at_end = nullptr) {
  World w(s);
  ProbeSet probes(s, w);
  Rows r;
  r.columns = probes.columns();
  for (int k = 1; k * s.output_interval <= t_end + 1e-12; ++k) {
    w.advance_to(k * s.output_interval, [] { return true; });
    std::vector<double> row{w.time()};
    const auto v = probes.measure(w);
    row.insert(row.end(), v.begin(), v.end());
    r.rows.push_back(row);
    r.outflow.push_back(w.count(Kind::Outflow));
  }
  if (at_end) at_end(w);
  return r;
}

// The open_boundary probe `bal` of a run: mass in - mass out = the change of the mass inside, up to
// round-off.
void check_mass_balance(const Rows& r) {
  const auto& a = r.rows.front();
  const auto& b = r.rows.back();
  auto col = [&](const std::string& name) {
    return std::find(r.columns.begin(), r.columns.end(), name) - r.columns.begin() + 1;
  };
  const double m_in = b[col("bal.mass_in")] - a[col("bal.mass_in")];
  const double m_out = b[col("bal.mass_out")] - a[col("bal.mass_out")];
  const double m_change = b[col("bal.mass_inside")] - a[col("bal.mass_inside")];
  CHECK(std::abs(m_in - m_out - m_change) < 1e-12 * b[col("bal.mass_inside")]);
}

}  // namespace

TEST_CASE("pressure inlet: a pressure drop drives Poiseuille flow through a tube, and backflow",
          "[physiology][long]") {
  // nu = 1e-3 m^2/s in a tube of radius R = 4 mm: Re = 2 R V / nu ~ 0.04, developed within R^2 / nu = 16 ms.
  // 40 Pa over 16 mm: V = R^2 dp / (8 mu L) = 5 mm/s. The density varies by dp / (rho c0^2) = 1 %.
  // At R = 4 spacings the open tube's resistance drifts down (the same with a velocity inlet; a periodic
  // tube of this size driven by a body force does not drift): the flow over the Poiseuille flow of the
  // measured gradient, 0.96 at 0.04-0.08 s, 0.94 at 0.12-0.16 s, 1.20 at 0.32-0.40 s, 1.45-1.58 at 0.9-1.2 s
  // (with the outlet before stop 48: 0.93, 0.88, 1.22, 1.3-1.5). Until stop 48 the flow was compared over
  // 0.04-0.4 s, where the drift happened to average out (ratio 1.005); it is compared now over 0.04-0.16
  // s, 2.5-10 viscous times: developed, before most of the drift (0.938; before stop 48 0.894). The drift
  // comes from the pressure level, 100-140 Pa over a 40 Pa drive (the SPH gradient's error grows with it; at
  // 40 / 0 Pa the tube carries 1.10-1.18, as the periodic one does); the background, the margin against
  // tension, keeps it here (docs/validation.md, stop 49; the "pressure gauge" test below).
  PTube t;
  const double dp = 40.0;
  for (const int sign : {1, -1}) {
    t.inlet = Waveform{{}, {100.0 + sign * dp}, 0.0, 0.0};
    t.outlet = 100.0;
    const Scene s = ptube(t);
    std::size_t inflow = 0, outflow = 0;
    const double t1 = sign > 0 ? 0.16 : 0.1, t0 = 0.04;
    const Rows r = run(s, t1, [&](const World& w) {
      inflow = w.count(Kind::Inflow);
      outflow = w.count(Kind::Outflow);
    });
    const double R = t.radius_dx * t.dx, L = t.length_dx * t.dx, mu = 1060.0 * t.nu;
    // The measured pressure gradient between the probes at L/4 and 3L/4 (the ends' entrance effects aside).
    const double G = (r.mean("p1", t0, t1) - r.mean("p2", t0, t1)) / (0.5 * L);
    const double q_poiseuille = M_PI * std::pow(R, 4) * G / (8.0 * mu);
    const double q_mid = r.mean("q_mid", t0, t1);
    const double q_in = r.mean("bal.inlet.flow", t0, t1), q_out = r.mean("bal.outlet.flow", t0, t1);
    INFO("sign " << sign << ": gradient " << G << " Pa/m (imposed " << sign * dp / L << "), mid flow "
                 << q_mid << ", inlet " << q_in << ", outlet " << q_out << ", Poiseuille " << q_poiseuille
                 << " m^3/s");
    CHECK(sign * G > 0.5 * dp / L);  // a real drop along the tube
    // Forwards: Poiseuille's law. Backwards (fluid leaves through the pressure inlet, enters through the
    // outlet), over a shorter run: the flow reverses, as large within the wander above.
    CHECK(std::abs(q_mid / q_poiseuille - 1.0) < (sign > 0 ? 0.10 : 0.15));
    // The boundaries' flow columns measure the same flow (positive into the domain at the inlet, out of it
    // at the outlet), and their pressure columns the imposed pressures.
    CHECK(std::abs(q_in / q_mid - 1.0) < 0.05);
    CHECK(std::abs(q_out / q_mid - 1.0) < 0.05);
    CHECK(r.mean("bal.inlet.pressure", t0, t1) == Approx(100.0 + sign * dp));
    CHECK(r.mean("bal.outlet.pressure", t0, t1) == Approx(100.0));
    // The buffers neither empty nor pile up, forwards or backwards.
    const std::size_t columns = 52;
    INFO("inflow buffer " << inflow << ", outflow buffer " << outflow);
    CHECK(inflow > 0.8 * t.layers * columns);
    CHECK(inflow < 1.2 * t.layers * columns);
    CHECK(outflow > 0.8 * t.layers * columns);
    CHECK(outflow < 1.2 * t.layers * columns);
    // The outflow buffer holds its lattice's count at every row: forwards it moves as the fluid at the disc
    // (carry_disc_velocity). Until stop 48 each layer of it took the velocity of the layer nearer the disc,
    // which smeared the parabola: the core's columns ran slower at the far face than at the disc and the
    // buffer piled up to 240 particles by 0.13 s (now at most 208 over this run's 0.16 s, 216 over 0.4 s;
    // backwards 220).
    const std::size_t most = *std::max_element(r.outflow.begin(), r.outflow.end());
    INFO("outflow buffer at most " << most);
    CHECK(most < 1.1 * t.layers * columns);
    check_mass_balance(r);
  }
}

TEST_CASE("pressure gauge: the flow through an open tube does not depend on the pressure level",
          "[physiology][long]") {
  // The Poiseuille tube above at c0 = 10 m/s, driven by 40 Pa, at two pressure levels: 140 / 100 Pa and
  // 1140 / 1100 Pa (the background 100 Pa both times; 1000 Pa compresses the blood by 0.9 %, as 120 mmHg
  // does the physio scene's). Only the difference drives an incompressible flow. The SPH pressure gradient
  // (eq. 9) is not exact for a uniform pressure on a disordered or unevenly packed lattice: its error grows
  // with the pressure itself, and at the higher level it held the fluid nearly still (flow over Poiseuille
  // 0.14 over 0.04-0.16 s, then ~0.02; 0.944 at the lower level) until the momentum equation measured the
  // pressure from the gauge, the lowest pressure an open boundary imposes less the background (stop 49):
  // now 0.955 at the higher level; at the lower the gauge is 0 and nothing changed. Compared over 0.04-0.10 s
  // since stop 63 (0.04-0.16 s before, the suite's longest case): 0.948 at both levels.
  PTube t;
  t.c0 = 10.0;
  const double dp = 40.0, t0 = 0.04, t1 = 0.10;
  auto ratio = [&](double level) {
    t.inlet = Waveform{{}, {100.0 + level + dp}, 0.0, 0.0};
    t.outlet = 100.0 + level;
    const Scene s = ptube(t);  // the gauge on: Scene's default, as the loader's
    double seen = -1.0;
    const Rows r = run(s, t1, [&](const World& w) { seen = w.fluid_context().gauge; });
    CHECK(seen == Approx(level));  // min(inlet, outlet) - background
    const double R = t.radius_dx * t.dx, L = t.length_dx * t.dx, mu = 1060.0 * t.nu;
    const double G = (r.mean("p1", t0, t1) - r.mean("p2", t0, t1)) / (0.5 * L);
    const double q_poiseuille = M_PI * std::pow(R, 4) * G / (8.0 * mu);
    const double q = r.mean("q_mid", t0, t1);
    UNSCOPED_INFO("level " << level << " Pa: gradient " << G << " Pa/m, flow " << q
                           << " m^3/s, over Poiseuille " << q / q_poiseuille);
    return q / q_poiseuille;
  };
  const double low = ratio(0.0), high = ratio(1000.0);
  CHECK(std::abs(low - 1.0) < 0.10);
  CHECK(std::abs(high - 1.0) < 0.10);
  CHECK(std::abs(high - low) < 0.05);
}

TEST_CASE("pressure inlet: a flow reversing at 50 Hz keeps every buffer column full", "[physiology][long]") {
  // The inlet pressure swings 2000 +- 1500 Pa at 50 Hz against 2000 Pa at the outlet, so the flow through
  // the inlet reverses every 10 ms (velocity amplitude dp / (rho L omega) ~ 0.3 m/s): fluid crosses the disc
  // both ways, and joins the buffer off its lattice when it flows back. Until stop 40 an entering particle
  // was replaced `layers` spacings behind itself only where no buffer particle was within half a spacing:
  // here that left 198 of the buffer's 208 particles at 0.15 s, a column with 3 of its 4, and 812 fluid
  // particles of 832 (a tube like it run on to 0.2 s from a scene file: 167 buffer particles left). The
  // buffer's columns must stay full, and the mass balance exact.
  PTube t;
  t.c0 = 10.0;
  t.nu = 3.3e-6;
  t.background = 2000.0;
  t.output_interval = 0.005;
  std::vector<double> ts, ps;
  for (int k = 0; k < 8; ++k) {
    ts.push_back(k * 0.0025);
    ps.push_back(1500.0 * std::sin(2.0 * M_PI * 50.0 * ts.back()));
  }
  t.inlet = Waveform{ts, ps, 0.02, 2000.0};
  t.outlet = 2000.0;
  const Scene s = ptube(t);
  std::map<std::pair<int, int>, int> columns;
  std::size_t fluid_start = 0, fluid_end = 0;
  {
    const World w0(s);
    fluid_start = w0.count(Kind::Fluid);
  }
  double q_min = 0.0, q_max = 0.0;
  const Rows r = run(s, 0.15, [&](const World& w) {
    const Particles& P = w.particles();
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.kind[i] == Kind::Inflow)
        ++columns[{static_cast<int>(std::floor(P.x[i].x() / t.dx)),
                   static_cast<int>(std::floor(P.x[i].z() / t.dx))}];
    fluid_end = w.count(Kind::Fluid);
  });
  const std::size_t cq =
      std::find(r.columns.begin(), r.columns.end(), "bal.inlet.flow") - r.columns.begin() + 1;
  for (const auto& row : r.rows) q_min = std::min(q_min, row[cq]), q_max = std::max(q_max, row[cq]);
  INFO("inlet flow " << q_min << " .. " << q_max << " m^3/s; fluid particles " << fluid_start << " -> "
                     << fluid_end);
  CHECK(q_min < -0.2 * q_max);  // the flow did reverse
  int fewest = 1000, total = 0;
  for (const auto& [c, n] : columns) fewest = std::min(fewest, n), total += n;
  INFO("buffer columns " << columns.size() << ", fewest particles in one " << fewest << ", all " << total);
  CHECK(columns.size() == 52);
  CHECK(fewest >= t.layers);
  CHECK(total <= 1.05 * t.layers * 52);
  CHECK(std::abs(static_cast<double>(fluid_end) / fluid_start - 1.0) < 0.05);
  check_mass_balance(r);
}

TEST_CASE("pressure inlet: with particle shifting, flow between equal pressures does not speed up by itself",
          "[physiology][long]") {
  // The same pressure, 6 kPa, at both ends of a tube 16 mm across and 32 mm long (2 mm spacing), the blood
  // moving at 0.5 m/s at the start: nothing drives the flow, so after the start-up (the column, at the 2 kPa
  // background, fills up to 6 kPa in the first few ms) it can only slow down, and shifting the particles
  // (A = 2) must not drive it. Before stop 42 the shift's part towards the tube wall pushed the near-wall
  // particles into the wall at every step and the pressure pushed them back; the shifted flow sped up by
  // itself: 92 -> 99 ml/s from 10-20 to 60-80 ms where the unshifted one slows, 93 -> 73 ml/s (in a 24 mm,
  // 44 mm long tube at c0 = 40 m/s, 456 -> 835 ml/s in 80 ms). Now a shift never moves a particle towards a
  // boundary (fluid/shifting.hpp): 94 -> 70 ml/s, the ratio 0.050 under the unshifted one (the part away from
  // the wall, which is kept, brakes a little); with the shift counted in the density (shifting_ale, stop 44)
  // 96 -> 70 ml/s, 0.063 under. (Counting the shift in the density alone, without the wall rule, also stops
  // the drive: 97 -> 71 ml/s, 0.056 under, in a temporary build. In a tube 24 mm across, the physio aorta's
  // size, the shipped rule without the density change drives a little, +0.032 over the unshifted ratio, and
  // with it +0.011.) Since stop 49 the momentum equation measures the pressure from the gauge (here 4 kPa,
  // docs/model.md "Pressure gauge"): unshifted 97 -> 86 ml/s, shifted 93 -> 81 ml/s, 0.018 under; both slow
  // less than before (the viscous time R^2 / nu is 19 s: nearly all of the loss was the gradient's error).
  PTube t;
  t.dx = 2e-3;
  t.radius_dx = 4;
  t.length_dx = 16;
  t.c0 = 20.0;
  t.nu = 3.3e-6;
  t.background = 2000.0;
  t.initial_velocity = 0.5;
  t.inlet = Waveform{{}, {6000.0}, 0.0, 0.0};
  t.outlet = 6000.0;
  t.output_interval = 0.001;
  auto change = [&](double shifting) {
    t.shifting = shifting;
    const Rows r = run(ptube(t), 0.08);
    const double early = r.mean("q_mid", 0.01, 0.02), late = r.mean("q_mid", 0.06, 0.08);
    UNSCOPED_INFO("shifting " << shifting << ": mid-tube flow " << early * 1e6 << " ml/s over 10-20 ms, "
                              << late * 1e6 << " ml/s over 60-80 ms");
    return late / early;
  };
  const double plain = change(0.0), shifted = change(2.0);
  CHECK(shifted < plain + 0.03);  // no drive forwards (before: +0.106)
  CHECK(shifted > plain - 0.08);  // nor a strong brake (now: -0.050)
}

TEST_CASE("windkessel outlet: the outlet pressure follows the RCR ODE driven by the measured flow",
          "[physiology][heavy]") {
  // A velocity inlet pushes 0.1 m/s through the tube into an RCR outlet: R_d C = 18 ms, and a constant flow
  // would charge it by Q (R_p + R_d) = 18 Pa. The outlet's pressure is integrated here again, independently
  // (Crank-Nicolson at each fluid step), from the flow the outlet measured, and compared; and the fluid next
  // to the outlet must carry that pressure.
  PTube t;
  t.nu = 3.3e-6;
  t.c0 = 2.0;
  t.velocity = 0.1;
  t.initial_velocity = 0.1;
  WindkesselParams wk;
  wk.proximal_resistance = 5e5;
  wk.capacitance = 6e-9;
  wk.distal_resistance = 3e6;
  wk.distal_pressure = 100.0;
  wk.initial_pressure = 100.0;
  t.windkessel = wk;
  const Scene s = ptube(t);
  World w(s);
  const auto& flows = w.open_boundaries().flows();
  REQUIRE(flows.size() == 2);
  double pc = wk.initial_pressure, q_prev = flows[1].flow, worst = 0.0, p_near = 0.0, p_imposed = 0.0;
  int near_samples = 0;
  Probe near;
  near.name = "near";
  near.type = ProbeType::Pressure;
  near.point = Vec3(0, (t.length_dx - 3) * t.dx, 0);
  Scene with_probe = s;
  with_probe.probes = {near};
  const ProbeSet probe(with_probe, w);
  const double A = 52 * t.dx * t.dx, tau = wk.distal_resistance * wk.capacitance;
  while (w.time() < 0.06 - 1e-12) {
    const double dt = std::min(w.stable_dt(), 0.06 - w.time());
    w.step(dt);
    const double q = flows[1].flow;
    // Crank-Nicolson: C (pc' - pc) / dt = (q + q_prev) / 2 - ((pc' + pc) / 2 - P_d) / R_d.
    const double a = 0.5 * dt / tau;
    pc = ((1.0 - a) * pc + 2.0 * a * wk.distal_pressure + 0.5 * dt / wk.capacitance * (q + q_prev)) /
         (1.0 + a);
    q_prev = q;
    const double expect = pc + wk.proximal_resistance * q;
    worst = std::max(worst, std::abs(flows[1].pressure - expect));
    if (w.time() > 0.03) {
      p_near += probe.measure(w)[0];
      p_imposed += flows[1].pressure;
      ++near_samples;
    }
  }
  const double rise = 0.1 * A * (wk.proximal_resistance + wk.distal_resistance);
  INFO("outlet pressure " << flows[1].pressure << " Pa, worst difference from the RCR ODE " << worst
                          << " Pa (constant-flow rise " << rise << " Pa); flow " << flows[1].flow
                          << " m^3/s");
  CHECK(worst < 0.01 * rise);
  // After 3 time constants the outlet has charged most of the way to the constant-flow value.
  CHECK(flows[1].pressure - wk.distal_pressure > 0.8 * rise);
  CHECK(flows[1].pressure - wk.distal_pressure < 1.2 * rise);
  // The fluid 3 spacings before the outlet carries the outlet's pressure (the drop over 3 spacings is small).
  p_near /= near_samples;
  p_imposed /= near_samples;
  INFO("mean pressure near the outlet " << p_near << " Pa, imposed " << p_imposed << " Pa");
  CHECK(std::abs(p_near - p_imposed) < 0.2 * rise);
}

namespace {

// A pressure inlet with a periodic waveform (the LV's shape, scaled down) into a Windkessel outlet, fluid
// moving both ways over the cycle.
Scene cycle_tube() {
  PTube t;
  t.nu = 1e-4;
  t.c0 = 5.0;
  t.length_dx = 8;
  t.output_interval = 0.001;
  t.initial_velocity = 0.2;  // particles cross both discs from the start
  t.inlet = Waveform{{0.0, 0.003, 0.006}, {100.0, 200.0, 40.0}, 0.008, 0.0};
  WindkesselParams wk;
  wk.proximal_resistance = 5e5;
  wk.capacitance = 6e-9;
  wk.distal_resistance = 3e6;
  wk.distal_pressure = 100.0;
  wk.initial_pressure = 105.0;
  t.windkessel = wk;
  return ptube(t);
}

}  // namespace

TEST_CASE("windkessel outlet and pressure inlet: a checkpoint continues bitwise",
          "[physiology][checkpoint]") {
  const Scene s = cycle_tube();
  World a(s);
  ProbeSet pa(s, a);
  a.advance_to(0.0035, [] { return true; });  // between two outputs: the averaging interval is saved too
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());
  World b(s);
  ProbeSet pb(s, b);
  b.load_state(in);
  CHECK(state_hash(b) == state_hash(a));
  for (int k = 4; k <= 8; ++k) {
    a.advance_to(0.001 * k, [] { return true; });
    b.advance_to(0.001 * k, [] { return true; });
    const auto va = pa.measure(a), vb = pb.measure(b);
    REQUIRE(va.size() == vb.size());
    for (std::size_t c = 0; c < va.size(); ++c) {
      INFO("t " << a.time() << ", column " << pa.columns()[c]);
      CHECK(std::memcmp(&va[c], &vb[c], sizeof(double)) == 0);
    }
  }
  CHECK(state_hash(b) == state_hash(a));
  const auto& fa = a.open_boundaries().flows();
  const auto& fb = b.open_boundaries().flows();
  CHECK(std::memcmp(&fa[1].windkessel.pc, &fb[1].windkessel.pc, sizeof(double)) == 0);
  CHECK(fa[1].windkessel.pc != 105.0);  // the Windkessel moved
  CHECK(a.open_boundaries().state().created > 0);
}

TEST_CASE("windkessel outlet and pressure inlet: identical probes and state for 1 and 2 threads",
          "[physiology][determinism][heavy]") {
  const Scene s = cycle_tube();
  std::vector<double> values[2];
  uint64_t hash[2];
  const int before = max_threads();
  for (int k = 0; k < 2; ++k) {
    set_threads(k + 1);
    World w(s);
    ProbeSet probes(s, w);
    for (int o = 1; o <= 6; ++o) {
      w.advance_to(0.001 * o, [] { return true; });
      const auto v = probes.measure(w);
      values[k].insert(values[k].end(), v.begin(), v.end());
    }
    hash[k] = state_hash(w);
    CHECK(w.open_boundaries().state().created > 0);
  }
  set_threads(before);
  CHECK(hash[0] == hash[1]);
  REQUIRE(values[0].size() == values[1].size());
  for (std::size_t i = 0; i < values[0].size(); ++i) {
    INFO("value " << i);
    CHECK(std::memcmp(&values[0][i], &values[1][i], sizeof(double)) == 0);
  }
}

TEST_CASE(
    "physiological boundaries: bad scene keys and waveform files are refused naming the key or file:line",
    "[physiology][bad-input]") {
  const fs::path dir = aortasph::test::scratch("physiology_bc");
  fs::create_directories(dir / "waveforms");
  auto write = [&](const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; };
  write("waveforms/good.csv", "# source: test\ntime_s,p_mmHg\n0, 8\n0.3, 120\n0.8, 8\n");
  write("waveforms/empty.csv", "# only a comment\n\n");
  write("waveforms/backwards.csv", "0, 8\n0.3, 120\n0.2, 100\n");
  write("waveforms/text.csv", "0, 8\n0.3, high\n");
  write("waveforms/three.csv", "0, 8, 9\n");
  auto file_inlet = [](const std::string& file) {
    return nlohmann::json{{"file", file}, {"units", "mmHg"}, {"period", 0.8}};
  };
  struct Case {
    std::string what;
    std::function<void(nlohmann::json&)> edit;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {"zero proximal resistance",
       [](nlohmann::json& j) { j["open_boundaries"][1]["windkessel"]["proximal_resistance"] = 0; },
       "open_boundaries[1].windkessel.proximal_resistance: must be positive"},
      {"negative capacitance",
       [](nlohmann::json& j) { j["open_boundaries"][1]["windkessel"]["capacitance"] = -1e-9; },
       "open_boundaries[1].windkessel.capacitance: must be positive"},
      {"negative distal resistance",
       [](nlohmann::json& j) { j["open_boundaries"][1]["windkessel"]["distal_resistance"] = -3e6; },
       "open_boundaries[1].windkessel.distal_resistance: must be positive"},
      {"missing distal pressure",
       [](nlohmann::json& j) { j["open_boundaries"][1]["windkessel"].erase("distal_pressure"); },
       "open_boundaries[1].windkessel.distal_pressure: missing"},
      {"unknown windkessel key",
       [](nlohmann::json& j) { j["open_boundaries"][1]["windkessel"]["inductance"] = 1; },
       "open_boundaries[1].windkessel.inductance: unknown key"},
      {"pressure and velocity", [](nlohmann::json& j) { j["open_boundaries"][0]["velocity"] = 0.1; },
       "open_boundaries[0].pressure: an inflow takes either 'velocity' or 'pressure', not both"},
      {"pressure and windkessel", [](nlohmann::json& j) { j["open_boundaries"][1]["pressure"] = 100; },
       "open_boundaries[1].windkessel: an outflow takes either 'pressure' or 'windkessel', not both"},
      {"profile on a pressure inlet",
       [](nlohmann::json& j) { j["open_boundaries"][0]["profile"] = "parabolic"; },
       "open_boundaries[0].profile: a pressure inlet has no prescribed profile"},
      {"missing file",
       [&](nlohmann::json& j) { j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/none.csv"); },
       "open_boundaries[0].pressure.file: " + (dir / "waveforms/none.csv").string() +
           ": no such waveform file"},
      {"empty file",
       [&](nlohmann::json& j) { j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/empty.csv"); },
       (dir / "waveforms/empty.csv").string() + ": no samples"},
      {"times not increasing",
       [&](nlohmann::json& j) {
         j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/backwards.csv");
       },
       (dir / "waveforms/backwards.csv").string() + ":3: times must increase strictly (0.2 after 0.3)"},
      {"non-numeric cell",
       [&](nlohmann::json& j) { j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/text.csv"); },
       (dir / "waveforms/text.csv").string() +
           ":2: expected two finite numbers (time, value), got '0.3, high'"},
      {"three cells",
       [&](nlohmann::json& j) { j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/three.csv"); },
       (dir / "waveforms/three.csv").string() + ":1: expected 2 cells"},
      {"unknown unit",
       [&](nlohmann::json& j) {
         j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/good.csv");
         j["open_boundaries"][0]["pressure"]["units"] = "kPa";
       },
       "open_boundaries[0].pressure.units: unknown value 'kPa' (expected one of: Pa, mmHg)"},
      {"zero period",
       [&](nlohmann::json& j) {
         j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/good.csv");
         j["open_boundaries"][0]["pressure"]["period"] = 0;
       },
       "open_boundaries[0].pressure.period: must be positive"},
      {"negative period",
       [&](nlohmann::json& j) {
         j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/good.csv");
         j["open_boundaries"][0]["pressure"]["period"] = -0.8;
       },
       "open_boundaries[0].pressure.period: must be positive"},
      {"period shorter than the table",
       [&](nlohmann::json& j) {
         j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/good.csv");
         j["open_boundaries"][0]["pressure"]["period"] = 0.5;
       },
       "open_boundaries[0].pressure.period: the waveform in"},
      {"pressure table backwards",
       [](nlohmann::json& j) {
         j["open_boundaries"][0]["pressure"] = {{0, 100}, {0, 120}};
       },
       "open_boundaries[0].pressure[1]: times must increase strictly"},
      {"unknown pressure gauge", [](nlohmann::json& j) { j["pressure_gauge"] = "lowest"; },
       "pressure_gauge: unknown value 'lowest' (expected one of: open_boundaries, none)"},
      {"pressure gauge not a string", [](nlohmann::json& j) { j["pressure_gauge"] = 0; },
       "pressure_gauge: expected a string"},
  };
  for (const Case& c : cases) {
    nlohmann::json j = tube_json();
    c.edit(j);
    std::ofstream(dir / "scene.json") << j.dump(2);
    std::string err;
    try {
      load_scene(dir / "scene.json", {});
    } catch (const InputError& e) {
      err = e.what();
    }
    INFO(c.what << ": '" << err << "'");
    CHECK(err.find(c.expect) != std::string::npos);
  }
  // The good file loads relative to the scene file's folder, from any working directory; '#' lines and the
  // header are skipped, mmHg converted, the offset added.
  nlohmann::json j = tube_json();
  j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/good.csv");
  j["open_boundaries"][0]["pressure"]["offset"] = 100.0;
  std::ofstream(dir / "scene.json") << j.dump(2);
  const LoadedScene l = load_scene(dir / "scene.json", {});
  const Waveform& w = l.scene.open_boundaries[0].inlet_pressure;
  CHECK(w.t == std::vector<double>{0.0, 0.3, 0.8});
  CHECK(w.at(0.3) == Approx(120.0 * kMmHg + 100.0));
  CHECK(w.at(1.1) == Approx(120.0 * kMmHg + 100.0));
  CHECK(l.resolved["open_boundaries"][0]["pressure"]["offset"] == 100.0);
  CHECK(l.scene.pressure_gauge_open);  // the default, written into the resolved scene
  CHECK(l.resolved["pressure_gauge"] == "open_boundaries");
  // From the command line: exit 2, the message on stderr.
  j["open_boundaries"][0]["pressure"] = file_inlet("waveforms/text.csv");
  std::ofstream(dir / "scene.json") << j.dump(2);
  std::string err;
  CHECK(aortasph::test::run_cli("check " + (dir / "scene.json").string(), err) == 2);
  CHECK(err.find("text.csv:2: expected two finite numbers") != std::string::npos);
  fs::remove_all(dir);
}

namespace {

// Starts the binary without a shell (the signal reaches aortasph itself); its exit code or 128 + signal.
pid_t spawn(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    static const std::string bin = AORTASPH_BINARY;
    argv.push_back(const_cast<char*>(bin.c_str()));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(bin.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

int wait_for(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

TEST_CASE(
    "pressure inlet from a waveform file and Windkessel outlet: SIGINT and resume give identical probes",
    "[physiology][checkpoint][cli][heavy]") {
  // The waveform file is found relative to the scene file's folder, on resume too; the run is interrupted
  // between outputs, so the flows' averaging interval and the Windkessel state travel in the checkpoint.
  const fs::path dir = aortasph::test::scratch("physiology_resume");
  fs::create_directories(dir / "scn" / "waveforms");
  std::ofstream(dir / "scn" / "waveforms" / "p.csv") << "# source: test\n0, 100\n0.003, 200\n0.006, 40\n";
  nlohmann::json j = tube_json();
  j["time"]["end"] = 0.012;
  j["time"]["output_interval"] = 0.001;
  j["materials"]["blood"]["viscosity"] = 1e-4;
  j["materials"]["blood"]["sound_speed"] = 5;
  j["bodies"][0]["velocity"] = {0, 0.2, 0};
  j["open_boundaries"][0]["pressure"] = {
      {"file", "waveforms/p.csv"}, {"units", "Pa"}, {"period", 0.008}, {"offset", 0}};
  const fs::path scene = dir / "scn" / "tube.json";
  std::ofstream(scene) << j.dump(2);
  const fs::path whole = dir / "whole", part = dir / "part";
  std::string err;
  REQUIRE(aortasph::test::run_cli("run " + scene.string() + " --quiet --no-render --out " + whole.string(),
                                  err) == 0);
  // The interrupted run names its scene relative to the folder it starts in, and is resumed from another:
  // the scene file is recorded as an absolute path (until stop 42 the relative one was, and a resume from
  // elsewhere found no waveform file).
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  const pid_t pid = spawn({"run", "scn/tube.json", "--quiet", "--no-render", "--checkpoint-every", "0.002",
                           "--out", part.string()});
  fs::current_path(cwd);
  for (int k = 0; k < 3000 && !fs::exists(part / "checkpoint.bin"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ::kill(pid, SIGINT);
  const int code = wait_for(pid);
  INFO("interrupted run: exit " << code);
  CHECK((code == 130 || code == 0));
  if (code == 130) {
    INFO(err);
    REQUIRE(aortasph::test::run_cli("resume " + part.string() + " --quiet", err) == 0);
    CHECK(aortasph::test::slurp(part / "run.json").find("resumed_at") != std::string::npos);
  }
  const nlohmann::json run = nlohmann::json::parse(aortasph::test::slurp(part / "run.json"));
  CHECK(fs::path(run["scene_file"].get<std::string>()) == fs::weakly_canonical(scene));
  const std::string probes = aortasph::test::slurp(part / "probes.csv");
  CHECK(std::count(probes.begin(), probes.end(), '\n') == 14);  // header, t = 0, 0.001, ..., 0.012
  CHECK(probes == aortasph::test::slurp(whole / "probes.csv"));
  fs::remove_all(dir);
}

TEST_CASE(
    "open_boundary probe: with probe rows between the frames, each row's flow is the mean since the last row",
    "[physiology][cli][heavy]") {
  // The pulsatile tube (scenes/tube_pulse.json) to 12 ms with a probe row every 2 ms, once with a frame at
  // every row (as shipped) and once with frames 12 ms apart (time.probe_interval): the steps land on the
  // rows either way, so the two runs are the same and so must their probes.csv be. Until stop 63 the
  // boundaries' flow columns were averaged from the last frame, not the last row: they differed from 4 ms
  // on (the physio scene's 1 ms rows carried the mean since its last 10 ms frame).
  const fs::path dir = aortasph::test::scratch("boundary_rows");
  const std::string scene = std::string(AORTASPH_TEST_DIR) + "/../scenes/tube_pulse.json";
  const std::string common = "run " + scene + " --quiet --no-render --threads 1 --end-time 0.012";
  std::string err;
  REQUIRE(aortasph::test::run_cli(common + " --out " + (dir / "frames").string(), err) == 0);
  REQUIRE(aortasph::test::run_cli(common +
                                      " --set time.output_interval=0.012 --set time.probe_interval=0.002" +
                                      " --out " + (dir / "rows").string(),
                                  err) == 0);
  const std::string frames = aortasph::test::slurp(dir / "frames" / "probes.csv");
  const std::string rows = aortasph::test::slurp(dir / "rows" / "probes.csv");
  CHECK(std::count(rows.begin(), rows.end(), '\n') == 8);  // header, t = 0, 0.002, ..., 0.012
  CHECK(frames.find("balance.lvot.flow") != std::string::npos);
  CHECK(rows == frames);
  fs::remove_all(dir);
}

TEST_CASE("scenes/aortic_valve_cycle_physio.json loads: the LV waveform inlet and the systemic RCR outlet",
          "[physiology][scene]") {
  const fs::path file = fs::path(AORTASPH_TEST_DIR) / ".." / "scenes" / "aortic_valve_cycle_physio.json";
  const Scene s = load_scene(file, {}).scene;
  REQUIRE(s.open_boundaries.size() == 2);
  const OpenBoundarySpec& lv = s.open_boundaries[0];
  const OpenBoundarySpec& ao = s.open_boundaries[1];
  REQUIRE(lv.pressure_inlet);
  REQUIRE(ao.windkessel);
  CHECK(lv.inlet_pressure.period == 0.8);
  // 0 mmHg is the fluid's background pressure (2000 Pa); the LV waveform starts at end diastole, 8 mmHg.
  CHECK((lv.inlet_pressure.at(0.0) - 2000.0) / kMmHg == Approx(8.076).epsilon(1e-3));
  CHECK(ao.windkessel->proximal_resistance * kMl / kMmHg == Approx(0.05).epsilon(1e-3));
  CHECK(ao.windkessel->capacitance * kMmHg / kMl == Approx(1.6).epsilon(1e-3));
  CHECK(ao.windkessel->distal_resistance * kMl / kMmHg == Approx(1.05).epsilon(1e-3));
  CHECK((ao.windkessel->initial_pressure - 2000.0) / kMmHg == Approx(80.0).epsilon(1e-3));
  // The sound speed carries a 16 kPa swing with a density change below 1 %.
  const Material& blood = s.materials[s.bodies[lv.body].material];
  CHECK(16e3 / (blood.density * blood.sound_speed * blood.sound_speed) < 0.01);
}

TEST_CASE("pressure inlet: the buffer's columns keep clear of a wall that is not on their lattice",
          "[physiology][heavy]") {
  // The aortic root's wall is rings of particles half a spacing outside the lumen, not the lattice the
  // inlet's columns are laid on: an inlet disc of the lumen's radius (13 mm, as the physio scene's) had a
  // ring of columns 0.5 spacings from the wall's first layer, and with the left-ventricular pressure behind
  // them their particles entered the wall above the disc (stop 40). A pressure inlet drops the columns within
  // 0.9 spacings of a body particle across its axis; a velocity inlet (flow prescribed per column) keeps all.
  auto lattice_columns = [](double radius, double dx) {
    const int nr = static_cast<int>(std::ceil(radius / dx));
    int n = 0;
    for (int j = -nr; j < nr; ++j)
      for (int i = -nr; i < nr; ++i) n += std::hypot((i + 0.5) * dx, (j + 0.5) * dx) < radius;
    return n;
  };
  for (const char* file : {"aortic_valve_cycle_physio.json", "aortic_root.json"}) {
    const Scene s = load_scene(std::string(AORTASPH_TEST_DIR) + "/../scenes/" + file,
                               {"resolution.spacing=0.0015", "aortic_root.leaflet_layers=2"})
                        .scene;
    const double dx = s.spacing;
    const OpenBoundarySpec& in = s.open_boundaries.at(0);
    REQUIRE(in.type == OpenBoundaryType::Inflow);
    const World w(s);
    const Particles& P = w.particles();
    double nearest = 1e300;  // lateral distance from a buffer particle to a wall particle beside the buffer
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (P.kind[i] != Kind::Inflow) continue;
      for (std::size_t k = 0; k < P.size(); ++k) {
        // Wall particles beside the buffer (between its far face and the disc; the normal is +y).
        const double a = P.x[k].y() - in.point.y();
        if (P.kind[k] != Kind::Wall || a < -in.layers * dx || a > 0.0) continue;
        nearest = std::min(nearest, std::hypot(P.x[k].x() - P.x[i].x(), P.x[k].z() - P.x[i].z()));
      }
    }
    const int all = lattice_columns(in.radius, dx);
    const std::size_t buffer = w.count(Kind::Inflow);
    INFO(file << ": buffer " << buffer << " particles in " << in.layers << " layers, " << all
              << " lattice columns within the radius; nearest wall particle across the axis " << nearest / dx
              << " spacings");
    if (in.pressure_inlet) {
      CHECK(nearest >= 0.9 * dx);
      CHECK(buffer < static_cast<std::size_t>(in.layers * all));  // the rim's columns went
      CHECK(buffer > static_cast<std::size_t>(0.8 * in.layers * all));
    } else {
      CHECK(nearest < 0.9 * dx);  // the velocity inlet's rim columns stay, close to the rings
      CHECK(buffer == static_cast<std::size_t>(in.layers * all));
    }
  }
}

TEST_CASE("scripts/physio_lumped.py: the shipped physio scene's boundary conditions ask for a normal cycle",
          "[physiology][cli]") {
  // The lumped model of scenes/aortic_valve_cycle_physio.json (its LV waveform and RCR across an ideal valve)
  // must land in issue 17's targets once periodic: aortic 110-130 / 70-90 mmHg, stroke volume 60-90 ml, peak
  // flow 350-550 ml/s (stop 42: 115.3 / 79.7 mmHg, 71.7 ml, 372 ml/s by the third cycle). A change to the
  // waveform or the RCR numbers that asks for an abnormal cycle fails here, before any SPH run.
  const fs::path root = fs::path(AORTASPH_TEST_DIR) / "..";
  const fs::path out = aortasph::test::scratch("lumped") / "out.csv";
  const std::string cmd = "/usr/bin/python3 " + (root / "scripts" / "physio_lumped.py").string() + " " +
                          (root / "scenes" / "aortic_valve_cycle_physio.json").string() + " --cycles 3 > " +
                          out.string() + " 2>&1";
  if (std::system("/usr/bin/python3 -c 'pass' > /dev/null 2>&1") != 0) {
    WARN("/usr/bin/python3 not found: scripts/physio_lumped.py not tested");
    return;
  }
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::istringstream text(aortasph::test::slurp(out));
  std::vector<double> last;
  for (std::string line; std::getline(text, line);) {
    if (line.empty() || !std::isdigit(static_cast<unsigned char>(line[0]))) continue;
    last.clear();
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) last.push_back(std::stod(cell));
  }
  // cycle, stroke volume, peak flow, aortic max, aortic min, ejection time, opening time, held time
  REQUIRE(last.size() == 8);
  INFO("cycle 3: " << last[1] << " ml, " << last[2] << " ml/s, aortic " << last[3] << " / " << last[4]
                   << " mmHg, ejection " << last[5] << " s, opening " << last[6] << " s, held " << last[7]
                   << " s");
  CHECK(last[0] == 3);
  CHECK(last[1] > 60.0);
  CHECK(last[1] < 90.0);
  CHECK(last[2] > 350.0);
  CHECK(last[2] < 550.0);
  CHECK(last[3] > 110.0);
  CHECK(last[3] < 130.0);
  CHECK(last[4] > 70.0);
  CHECK(last[4] < 90.0);
  // The valve opens in the waveform's upstroke and holds 70 mmHg only while shut: within the 0.8 s period
  // less the ejection, and for most of it (stop 58: opening 0.137 s, held 0.328 s of the 0.492 s shut).
  CHECK(last[6] > 0.05);
  CHECK(last[6] < 0.25);
  CHECK(last[7] <= 0.8 - last[5] + 1e-9);
  CHECK(last[7] > 0.5 * (0.8 - last[5]));
  // A scene without a pressure inlet and an RCR outlet is refused with exit 2.
  const std::string bad = "/usr/bin/python3 " + (root / "scripts" / "physio_lumped.py").string() + " " +
                          (root / "scenes" / "tube_flow.json").string() + " > /dev/null 2>&1";
  const int status = std::system(bad.c_str());
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 2);
}
