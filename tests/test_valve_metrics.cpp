// Valve metrics per cardiac cycle (issue 17 items 4-6; docs/valve-metrics.md): the metrics on synthetic time
// series with known answers, the probes they read (coaptation, stress percentile), a short run with a cycle
// block (cycles.csv, run.json, the Wiggers plot) and bad cycle blocks.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cli_helpers.hpp"
#include "core/parallel.hpp"
#include "cycle_report.hpp"
#include "io/probes.hpp"
#include "physiology/valve_metrics.hpp"
#include "scene_loader.hpp"
#include "world.hpp"

using namespace aortasph;
namespace fs = std::filesystem;
using aortasph::test::run_cli;
using aortasph::test::scratch;
using aortasph::test::slurp;

namespace {

constexpr double kPi = std::numbers::pi;

// Piecewise-linear function through (t, v) knots.
double pwl(const std::vector<std::pair<double, double>>& knots, double t) {
  if (t <= knots.front().first) return knots.front().second;
  for (std::size_t k = 1; k < knots.size(); ++k)
    if (t <= knots[k].first) {
      const auto [t0, v0] = knots[k - 1];
      const auto [t1, v1] = knots[k];
      return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
    }
  return knots.back().second;
}

// A synthetic valve cycle of period T = 0.8 s sampled every 1 ms over `cycles` cycles: half-sine forward flow
// of peak q_peak[k] over [0, 0.3] s, a triangular closing backflow (peak 100 ml/s, 0.300-0.336 s), then a
// leak of 2 ml/s from 0.340 s; orifice area 0 -> 3 cm^2 over 0.010-0.050 s, held, back to 0 over 0.300-0.340
// s; LV - aortic = 10 mmHg during ejection; aortic - LV = 80 mmHg once closed (aortic pressure edp[k] mmHg
// at the end of diastole, continuous across the cycle boundary).
CycleSignals synthetic(const std::vector<double>& q_peak, const std::vector<double>& edp) {
  CycleSignals s;
  const double T = 0.8, mmHg = kPaPerMmHg;
  const int per = 800;
  const int n = per * static_cast<int>(q_peak.size());
  for (int i = 0; i <= n; ++i) {
    // Samples (k T, (k+1) T] belong to cycle k: the sample at a cycle's end has that cycle's end-diastolic
    // values.
    const int k = i > 0 ? (i - 1) / per : 0;
    const double t = i * 1e-3, tau = t - k * T;
    double q = 0.0;
    if (tau <= 0.3)
      q = q_peak[k] * std::sin(kPi * tau / 0.3);
    else
      q = pwl({{0.3, 0}, {0.318, -100e-6}, {0.336, 0}, {0.340, -2e-6}, {0.8, -2e-6}}, tau);
    const double area = pwl({{0, 0}, {0.01, 0}, {0.05, 3e-4}, {0.3, 3e-4}, {0.34, 0}, {0.8, 0}}, tau);
    const double ao = edp[k] * mmHg + 1000.0 * std::sin(2 * kPi * tau / T);
    const double dp =
        tau <= 0.3 ? 10 * mmHg : pwl({{0.3, 10 * mmHg}, {0.336, -80 * mmHg}, {0.8, -80 * mmHg}}, tau);
    s.t.push_back(t);
    s.valve_flow.push_back(q);
    s.orifice_area.push_back(area);
    s.aortic_pressure.push_back(ao);
    s.lv_pressure.push_back(ao + dp);
    s.jet_speed.push_back(q / 1.5e-4);  // a jet of 1.5 cm^2
  }
  return s;
}

}  // namespace

TEST_CASE("valve metrics: half-sine ejection, Gorlin and continuity EOA, opening and closing",
          "[physiology]") {
  const double qp = 400e-6;  // 400 ml/s
  const CycleSignals s = synthetic({qp}, {80.0});
  CycleOptions o;
  o.period = 0.8;
  o.lvot_area = 3.5e-4;
  o.density = 1060.0;
  o.hold_level = 70 * kPaPerMmHg;
  const auto cycles = all_cycle_metrics(s, o);
  REQUIRE(cycles.size() == 1);
  const CycleMetrics& m = cycles[0];
  // Stroke volume: the half-sine's volume 2 q_p T_e / pi = 76.39 ml, within 0.1 %.
  const double sv = 2 * qp * 0.3 / kPi * 1e6;
  CHECK(m.stroke_volume_ml == Approx(sv).epsilon(1e-3));
  CHECK(m.cardiac_output_l_min == Approx(sv / 0.8 * 60 / 1e3).epsilon(1e-3));
  CHECK(m.peak_forward_flow_ml_s == Approx(400.0).epsilon(1e-4));
  CHECK(m.ejection_time_ms == Approx(300.0).epsilon(1e-3));
  CHECK(m.mean_gradient_mmHg == Approx(10.0).epsilon(1e-9));
  CHECK(m.peak_gradient_mmHg == Approx(10.0).epsilon(1e-9));
  // Gorlin (ISO 5840): q_rms of a half-sine is q_p / sqrt(2); EOA = q_rms / (51.6 sqrt(dp / rho)).
  const double eoa = 400.0 / std::sqrt(2.0) / (51.6 * std::sqrt(10.0 / 1.06));
  CHECK(m.eoa_gorlin_cm2 == Approx(eoa).epsilon(1e-3));
  // Continuity: A_LVOT VTI_LVOT / VTI_jet = SV / VTI_jet = the jet's 1.5 cm^2.
  CHECK(m.eoa_continuity_cm2 == Approx(1.5).epsilon(1e-6));
  CHECK(m.peak_jet_velocity_m_s == Approx(qp / 1.5e-4).epsilon(1e-4));
  CHECK(m.peak_goa_cm2 == Approx(3.0).epsilon(1e-9));
  // 10 % -> 90 % of the area's swing: 0.014 -> 0.046 s opening, 0.304 -> 0.336 s closing.
  CHECK(m.opening_time_ms == Approx(32.0).epsilon(1e-6));
  CHECK(m.closing_time_ms == Approx(32.0).epsilon(1e-6));
  // Closing volume: the triangle 0.300-0.336 s, 100 ml/s high: 1.8 ml. Leakage from closure (0.336 s) to the
  // cycle's end: 2 ml/s over 0.460 s plus the ramp 0.336-0.340 s: 0.924 ml.
  CHECK(m.closing_volume_ml == Approx(1.8).epsilon(1e-6));
  CHECK(m.leakage_volume_ml == Approx(0.924).epsilon(1e-6));
  CHECK(m.regurgitant_fraction_pct == Approx(100 * (1.8 + 0.924) / sv).epsilon(1e-3));
  // Diastolic difference: 80 mmHg held from closure (0.336 s) to 0.8 s; above 70 mmHg from 0.3315 s on
  // (the ramp from +10 to -80 mmHg crosses -70 mmHg at 0.332 s), counted from closure: 0.464 s.
  CHECK(m.diastolic_dp_mean_mmHg == Approx(80.0).epsilon(1e-9));
  CHECK(m.diastolic_dp_held_s == Approx(0.464).epsilon(1e-6));
  CHECK(m.aortic_end_diastolic_mmHg == Approx(80.0).epsilon(1e-6));
  // Not measured: stress, strain, coaptation -> NaN (written empty).
  CHECK(std::isnan(m.stress_diastole_peak_kPa));
  CHECK(std::isnan(m.effective_height_mm));
}

TEST_CASE("valve metrics: cycle windows and the periodic-state test", "[physiology]") {
  CycleOptions o;
  o.period = 0.8;
  CHECK(cycle_windows(2.4, o).size() == 3);
  CHECK(cycle_windows(2.3999, o).size() == 2);
  o.start = 0.1;
  const auto w = cycle_windows(2.4, o);
  REQUIRE(w.size() == 2);
  CHECK(w[1].first == Approx(0.9));
  CHECK(w[1].second == Approx(1.7));
  o.start = 0.0;
  // Stroke volumes 70, +3 %, +1 %, +1 % with end-diastolic pressures 80, 80, 80, 82 mmHg (+2.5 %).
  const double q = 70e-6 * kPi / 0.6;
  const CycleSignals s = synthetic({q, 1.03 * q, 1.0403 * q, 1.050703 * q}, {80, 80, 80, 82});
  const auto c = all_cycle_metrics(s, o);
  REQUIRE(c.size() == 4);
  CHECK(c[0].stroke_volume_ml == Approx(70).epsilon(1e-3));
  CHECK(std::isnan(c[0].sv_change_pct));
  CHECK(!c[0].periodic);
  CHECK(c[1].sv_change_pct == Approx(3.0).epsilon(1e-3));
  CHECK(!c[1].periodic);
  CHECK(c[2].sv_change_pct == Approx(1.0).epsilon(1e-3));
  CHECK(c[2].edp_change_pct == Approx(0.0).margin(1e-9));
  CHECK(c[2].periodic);
  CHECK(c[3].edp_change_pct == Approx(2.5).epsilon(1e-6));
  CHECK(!c[3].periodic);
  // The table has one column per metric, with the units in the names.
  const auto table = metric_table(c[3]);
  CHECK(table.front().first == "cycle");
  CHECK(table.back().first == "periodic");
  CHECK(table.back().second == 0.0);
}

TEST_CASE("probes for the valve metrics: stress percentile and coaptation of the closed aortic valve",
          "[physiology][long]") {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);
  CHECK(percentile_nearest_rank(v, 95.0) == 95.0);
  CHECK(percentile_nearest_rank({3.0}, 95.0) == 3.0);
  CHECK(percentile_nearest_rank({}, 95.0) == 0.0);

  // The closed valve of aortic_root.json at t = 0: the three leaflets meet along all three coaptation lines
  // and at the centre, below the commissures.
  const std::string file = std::string(AORTASPH_TEST_DIR) + "/../scenes/aortic_root.json";
  Scene s = load_scene(file, {}).scene;
  Probe c;
  c.name = "coapt";
  c.type = ProbeType::Coaptation;
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    if (s.bodies[b].name.rfind("leaflet", 0) == 0) c.bodies.push_back(static_cast<int>(b));
  REQUIRE(c.bodies.size() == 3);
  const AorticRootParams& geo = s.bodies[c.bodies[0]].shape.aortic;
  c.point = geo.base;
  c.normal = Vec3::UnitY();
  c.distance = 1.5 * s.spacing;
  c.central_radius = 2.0 * s.spacing;
  s.probes = {c};
  const World w(s);
  const ProbeSet probes(s, w);
  const auto values = probes.measure(w);
  REQUIRE(probes.columns().size() == 8);
  CHECK(probes.columns()[0] == "coapt.height_0_1");
  for (int p = 0; p < 3; ++p) {
    INFO("pair " << p << ": coaptation height " << values[2 * p] * 1e3 << " mm, length "
                 << values[2 * p + 1] * 1e3 << " mm");
    CHECK(values[2 * p] > 2 * s.spacing);
    CHECK(values[2 * p + 1] > 0.5 * geo.annulus_radius);  // from the centre most of the way to the wall
  }
  INFO("central coaptation height " << values[6] * 1e3 << " mm, effective height " << values[7] * 1e3
                                    << " mm");
  CHECK(values[6] > 0.0);
  CHECK(values[7] > 0.0);
  CHECK(values[7] < geo.commissure_height);
}

namespace {

// tube_flow at 2 mm with two 60 ms pulses and a cycle block; the file written into dir.
fs::path tube_cycle_scene(const fs::path& dir, const nlohmann::json& cycle) {
  std::ifstream in(std::string(AORTASPH_TEST_DIR) + "/../scenes/tube_flow.json");
  nlohmann::json s = nlohmann::json::parse(in);
  s["name"] = "tube_cycle";
  s["resolution"]["spacing"] = 0.002;
  s["time"] = {{"output_interval", 0.002}, {"cfl", 0.25}, {"max_dt", 1e-3}};
  const double T = 0.06;
  nlohmann::json table = nlohmann::json::array();
  for (int k = 0; k < 2; ++k)
    for (const auto& [t, v] : {std::pair{0.0, 0.0}, {0.015, 0.3}, {0.03, 0.0}})
      table.push_back({k * T + t, v});
  table.push_back({2 * T, 0.0});
  s["open_boundaries"][0]["velocity"] = table;
  s["probes"].push_back({{"name", "jet"},
                         {"type", "max_speed"},
                         {"region", {{"min", {-0.006, 0.015, -0.006}}, {"max", {0.006, 0.025, 0.006}}}}});
  s["cycle"] = cycle;
  s.erase("render");
  const fs::path file = dir / "tube_cycle.json";
  std::ofstream(file) << s.dump(1);
  return file;
}

nlohmann::json good_cycle() {
  return {
      {"period", 0.06},        {"cycles", 2},          {"lv_pressure", "p_in"}, {"aortic_pressure", "p_out"},
      {"valve_flow", "q_mid"}, {"lvot_flow", "q_out"}, {"jet_speed", "jet"}};
}

}  // namespace

TEST_CASE("cycle block: a short pulsatile tube run writes cycles.csv, run.json metrics and the Wiggers plot",
          "[physiology][cli][long]") {
  const fs::path dir = scratch("valve_cycle");
  const fs::path scene = tube_cycle_scene(dir, good_cycle());
  const fs::path out = dir / "out";
  std::string err;
  REQUIRE(run_cli("run " + scene.string() + " --out " + out.string() + " --threads 1 --no-render --quiet",
                  err) == 0);
  // time.end follows the cycles: 2 x 60 ms.
  const nlohmann::json run = nlohmann::json::parse(slurp(out / "run.json"));
  CHECK(run["time"]["simulated"].get<double>() == Approx(0.12));
  // One complete row per cycle: the metrics the tube's probes give are all there.
  const CsvTable cycles = read_csv(out / "cycles.csv");
  REQUIRE(cycles.rows.size() == 2);
  for (const char* name : {"stroke_volume_ml", "cardiac_output_l_min", "peak_forward_flow_ml_s",
                           "peak_jet_velocity_m_s", "peak_gradient_mmHg", "mean_gradient_mmHg",
                           "eoa_gorlin_cm2", "eoa_continuity_cm2", "aortic_end_diastolic_mmHg"}) {
    const int k = cycles.column(name);
    INFO(name);
    REQUIRE(k >= 0);
    for (const auto& row : cycles.rows) CHECK(std::isfinite(row[k]));
  }
  CHECK(cycles.rows[0][cycles.column("stroke_volume_ml")] > 0.0);
  // No valve: the orifice metrics are empty, not zero.
  CHECK(std::isnan(cycles.rows[1][cycles.column("peak_goa_cm2")]));
  CHECK(std::isfinite(cycles.rows[1][cycles.column("sv_change_pct")]));
  // run.json: every cycle, the periodic-state test and the cycle the metrics come from (the last).
  const auto& c = run["cycles"];
  CHECK(c["complete"] == 2);
  CHECK(c["per_cycle"].size() == 2);
  CHECK(c["metrics_from_cycle"] == 1);
  CHECK(c["metrics"]["stroke_volume_ml"].get<double>() ==
        Approx(cycles.rows[1][cycles.column("stroke_volume_ml")]));
  CHECK(c["periodic_state"].is_boolean());
  CHECK(c["per_cycle"][0]["periodic"].is_null());

  // aortasph plot on the finished run: a PNG (CI installs python3-matplotlib; here it may be absent).
  const bool matplotlib = std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") == 0 ||
                          std::system("python3 -c 'import matplotlib' > /dev/null 2>&1") == 0;
  if (!matplotlib) {
    WARN("python3 with matplotlib not found: aortasph plot not tested");
    return;
  }
  fs::remove(out / "figures" / "wiggers.png");
  REQUIRE(run_cli("plot " + out.string(), err) == 0);
  const std::string png = slurp(out / "figures" / "wiggers.png");
  CHECK(png.size() > 10000);
  CHECK(png.substr(1, 3) == "PNG");
  // A probes.csv without the columns the cycle block names: exit 2 naming the key and the column.
  { std::ofstream(out / "probes.csv") << "time,q_mid\n0,0\n0.06,0\n"; }
  CHECK(run_cli("plot " + out.string(), err) == 2);
  CHECK(err.find("cycle.lv_pressure") != std::string::npos);
  CHECK(run_cli("plot " + (dir / "missing").string(), err) == 2);
  CHECK(err.find("no such folder") != std::string::npos);
}

TEST_CASE("cycle block: bad input exits 2 naming the JSON path", "[physiology][bad-input]") {
  const fs::path dir = scratch("valve_cycle_bad");
  struct Case {
    std::string key;
    nlohmann::json value;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {"colour", "red", "cycle.colour: unknown key"},
      {"lv_pressure", "p_nowhere", "cycle.lv_pressure: no probe writes a column 'p_nowhere'"},
      {"lv_pressure", "p_in.mean", "cycle.lv_pressure: no probe writes a column 'p_in.mean'"},
      {"period", 0.0, "cycle.period: must be positive"},
      {"period", -0.06, "cycle.period: must be positive"},
      {"stress", "q_mid", "cycle.stress: probe 'q_mid' is not a stress probe"},
      {"cycles", 0, "cycle.cycles: expected an integer in 1..100000"},
  };
  for (const Case& c : cases) {
    nlohmann::json cycle = good_cycle();
    cycle[c.key] = c.value;
    const fs::path scene = tube_cycle_scene(dir, cycle);
    std::string err;
    INFO(c.key << " = " << c.value.dump());
    CHECK(run_cli("check " + scene.string(), err) == 2);
    INFO(err);
    CHECK(err.find(c.expect) != std::string::npos);
  }
  // A missing required column key, and no time.end without cycles.
  nlohmann::json cycle = good_cycle();
  cycle.erase("valve_flow");
  std::string err;
  CHECK(run_cli("check " + tube_cycle_scene(dir, cycle).string(), err) == 2);
  CHECK(err.find("cycle.valve_flow: missing") != std::string::npos);
  cycle = good_cycle();
  cycle.erase("cycles");
  CHECK(run_cli("check " + tube_cycle_scene(dir, cycle).string(), err) == 2);
  CHECK(err.find("time.end: missing") != std::string::npos);
}

TEST_CASE("stress probe: 95th percentile and peak strain of a sagging cantilever", "[physiology]") {
  // A clamped rubber beam sagging under gravity: its leaflet-style stress columns after 20 ms. One thread:
  // the beam has 80 particles, too few to share (on a loaded machine, idle threads cost more than the work).
  struct OneThread {
    int before = max_threads();
    OneThread() { set_threads(1); }
    ~OneThread() { set_threads(before); }
  } one_thread;
  Scene s;
  s.name = "beam";
  s.spacing = 0.005;
  s.gravity = Vec3(0, -9.81, 0);
  s.domain = {Vec3(-0.02, -0.05, -0.02), Vec3(0.1, 0.03, 0.03)};  // small: a small cell grid
  Material rubber;
  rubber.name = "rubber";
  rubber.type = MaterialType::Elastic;
  rubber.density = 1000.0;
  rubber.youngs_modulus = 2e4;
  rubber.poisson_ratio = 0.3;
  s.materials = {rubber};
  Body b;
  b.name = "beam";
  b.material = 0;
  b.shape.kind = ShapeKind::Box;
  b.shape.box = {Vec3(-0.01, 0, 0), Vec3(0.08, 0.01, 0.01)};
  b.fixed = Box{Vec3(-0.02, -0.05, -0.02), Vec3(0, 0.03, 0.03)};
  s.bodies = {b};
  Probe p;
  p.name = "st";
  p.type = ProbeType::Stress;
  p.bodies = {0};
  s.probes = {p};
  World w(s);
  const ProbeSet probes(s, w);
  REQUIRE(probes.columns() == std::vector<std::string>{"st.max", "st.mean", "st.p95", "st.strain_max"});
  w.advance_to(0.02, [] { return true; });
  const auto v = probes.measure(w);
  INFO("steps " << w.steps() << ", dt " << w.last_dt());
  INFO("max " << v[0] << " Pa, mean " << v[1] << " Pa, p95 " << v[2] << " Pa, strain " << v[3]);
  CHECK(v[0] > 0.0);
  CHECK(v[2] > 0.0);
  CHECK(v[2] <= v[0]);
  // The percentile against the particles' values, and the strain against E = (F^T F - I) / 2 of each one.
  const Solids& S = w.solids();
  std::vector<double> vm;
  double strain = 0.0;
  for (std::size_t k = 0; k < S.size(); ++k) {
    vm.push_back(S.von_mises(k));
    const Eigen::Matrix3d E = 0.5 * (S.F(k).transpose() * S.F(k) - Eigen::Matrix3d::Identity());
    strain = std::max(strain, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(E).eigenvalues().maxCoeff());
  }
  std::sort(vm.begin(), vm.end());
  CHECK(v[2] == vm[static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(vm.size()))) - 1]);
  CHECK(v[3] == Approx(strain).epsilon(1e-12));
  CHECK(v[3] > 0.0);
}
