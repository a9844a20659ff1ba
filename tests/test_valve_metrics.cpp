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
#include <tuple>

#include "cli_helpers.hpp"
#include "core/parallel.hpp"
#include "cycle_report.hpp"
#include "geometry/aortic_root.hpp"
#include "io/probes.hpp"
#include "physiology/coaptation.hpp"
#include "physiology/orifice.hpp"
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

TEST_CASE("valve metrics: the slow forward flow of bulging closed leaflets before opening is not ejection",
          "[physiology]") {
  // The synthetic cycle with a later, shorter ejection: a half-sine of 400 ml/s over 0.1-0.3 s, and before
  // it, from 0.02 s, the closed leaflets' bulge read as a forward flow of 2-13 ml/s (1-3 % of the peak,
  // wobbling as physio55n's cycle 2 did) while the LV is 50 mmHg below the aorta. The old definition (the
  // last zero crossing before the peak) started ejection at 0.02 s: 280 ms, mean gradient -7.1 mmHg.
  CycleSignals s = synthetic({400e-6}, {80.0});
  const double qp = 400e-6;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    const double tau = s.t[i];
    if (tau > 0.3) break;
    double q = 0.0;
    if (tau >= 0.1)
      q = qp * std::sin(kPi * (tau - 0.1) / 0.2);
    else if (tau > 0.02)
      q = (7.5 + 5.5 * std::sin(2 * kPi * tau / 0.013)) * 1e-6;
    s.valve_flow[i] = q;
    s.lv_pressure[i] = s.aortic_pressure[i] + (tau >= 0.1 ? 10.0 : -50.0) * kPaPerMmHg;
  }
  CycleOptions o;
  o.period = 0.8;
  const auto cycles = all_cycle_metrics(s, o);
  REQUIRE(cycles.size() == 1);
  const CycleMetrics& m = cycles[0];
  // The onset: the 5 % crossing (0.1 + 0.2 asin(0.05) / pi = 0.10318 s) taken back along the chord through
  // the 10 % crossing (0.10638 s) to 0.09998 s.
  CHECK(m.ejection_time_ms == Approx(200.0).epsilon(2e-3));
  CHECK(m.mean_gradient_mmHg == Approx(10.0).epsilon(2e-3));
  // The half-sine's volume 2 q_p T_e / pi = 50.93 ml; the bulge's 0.6 ml before it is not stroke volume.
  CHECK(m.stroke_volume_ml == Approx(2 * qp * 0.2 / kPi * 1e6).epsilon(2e-3));
}

TEST_CASE("valve metrics: the diastolic hold counts the previous diastole's tail at the window's start",
          "[physiology]") {
  // The synthetic cycle with the closed valve holding 80 mmHg over its first 9 ms (the last diastole's
  // tail: the valve opens from 10 ms), then the ejection's -10 mmHg from 10 ms. The ramp 9 -> 10 ms crosses
  // 70 mmHg at 9.111 ms: held 0.464 s from the closure plus 9.111 ms before the opening.
  CycleSignals s = synthetic({400e-6}, {80.0});
  for (std::size_t i = 0; i < s.t.size() && s.t[i] < 0.0095; ++i)
    s.lv_pressure[i] = s.aortic_pressure[i] - 80 * kPaPerMmHg;
  CycleOptions o;
  o.period = 0.8;
  o.hold_level = 70 * kPaPerMmHg;
  const auto cycles = all_cycle_metrics(s, o);
  REQUIRE(cycles.size() == 1);
  CHECK(cycles[0].diastolic_dp_held_s == Approx(0.464 + 0.009 + 0.001 / 9).epsilon(1e-6));
  // The mean over the window's own diastole (closure to the end) is unchanged.
  CHECK(cycles[0].diastolic_dp_mean_mmHg == Approx(80.0).epsilon(1e-9));
}

TEST_CASE("valve metrics: pressure_zero moves the LV and aortic pressures and no pressure difference",
          "[physiology]") {
  // The fluid's pressures are absolute in its terms (a 2000 Pa background in the physio scene); clinical ones
  // read 0 mmHg at rest. The synthetic cycle with 2000 Pa added to both pressures and pressure_zero 2000 Pa
  // reads as the cycle without them; with pressure_zero 0 its LV and aortic pressures read 15.0 mmHg high.
  const CycleSignals s = synthetic({400e-6}, {80.0});
  CycleSignals lifted = s;
  for (double& p : lifted.lv_pressure) p += 2000.0;
  for (double& p : lifted.aortic_pressure) p += 2000.0;
  CycleOptions o;
  o.period = 0.8;
  o.hold_level = 70 * kPaPerMmHg;
  const CycleMetrics base = all_cycle_metrics(s, o).at(0);
  const CycleMetrics raw = all_cycle_metrics(lifted, o).at(0);
  o.pressure_zero = 2000.0;
  const CycleMetrics zeroed = all_cycle_metrics(lifted, o).at(0);
  const double lift = 2000.0 / kPaPerMmHg;  // 15.0 mmHg
  for (const auto& [a, b, c] :
       {std::tuple{base.aortic_systolic_mmHg, raw.aortic_systolic_mmHg, zeroed.aortic_systolic_mmHg},
        {base.aortic_diastolic_mmHg, raw.aortic_diastolic_mmHg, zeroed.aortic_diastolic_mmHg},
        {base.aortic_end_diastolic_mmHg, raw.aortic_end_diastolic_mmHg, zeroed.aortic_end_diastolic_mmHg},
        {base.lv_peak_mmHg, raw.lv_peak_mmHg, zeroed.lv_peak_mmHg},
        {base.lv_end_diastolic_mmHg, raw.lv_end_diastolic_mmHg, zeroed.lv_end_diastolic_mmHg}}) {
    CHECK(b == Approx(a + lift).epsilon(1e-12));
    CHECK(c == Approx(a).margin(1e-9));
  }
  CHECK(base.aortic_end_diastolic_mmHg == Approx(80.0).epsilon(1e-6));
  // Differences do not depend on the zero.
  CHECK(zeroed.peak_gradient_mmHg == Approx(raw.peak_gradient_mmHg).epsilon(1e-12));
  CHECK(zeroed.mean_gradient_mmHg == Approx(raw.mean_gradient_mmHg).epsilon(1e-12));
  CHECK(zeroed.diastolic_dp_mean_mmHg == Approx(raw.diastolic_dp_mean_mmHg).epsilon(1e-12));
  CHECK(zeroed.diastolic_dp_held_s == Approx(raw.diastolic_dp_held_s).epsilon(1e-12));
  CHECK(zeroed.eoa_gorlin_cm2 == Approx(raw.eoa_gorlin_cm2).epsilon(1e-12));
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

TEST_CASE("coaptation height: the band two leaflets share and not the drop of their free edge",
          "[physiology]") {
  // Two sheets of points facing each other across the plane x = 0, one spacing apart, along a coaptation
  // line running out from the axis (r = z) to 10 mm; each shares a band 4 mm high with the other, under a
  // free edge that rises by 0.8 mm per mm towards the commissure (as a closed valve's lines do). A third
  // leaflet stands apart. The line's contact particles span 4 + 8 mm in height; the coaptation height is
  // the band's 4 mm.
  const double dx = 0.5e-3, band = 4e-3, slope = 0.8, reach = 10e-3;
  std::vector<Vec3> x;
  std::vector<int> leaf;
  for (int side = 0; side < 2; ++side)
    for (double zr = 0.0; zr <= reach + 1e-12; zr += dx)
      for (double depth = 0.0; depth <= band + 1e-12; depth += dx) {
        x.push_back(Vec3((side ? 0.5 : -0.5) * dx, 5e-3 + slope * zr - depth, zr));
        leaf.push_back(side);
      }
  for (double zr = 0.0; zr <= reach; zr += dx) {
    x.push_back(Vec3(-6e-3, 5e-3, -zr));
    leaf.push_back(2);
  }
  const auto c = coaptation_stats(x, leaf, 3, Vec3::Zero(), Vec3::UnitY(), 1.5 * dx, 2 * dx, dx);
  REQUIRE(c.height.size() == 3);
  INFO("height " << c.height[0] * 1e3 << " mm, length " << c.length[0] * 1e3 << " mm");
  CHECK(c.height[0] == Approx(band).margin(1e-9));
  CHECK(c.length[0] == Approx(std::hypot(0.5 * dx, reach) - 0.5 * dx).margin(1e-9));  // r from the axis
  CHECK(c.height[1] == 0.0);
  CHECK(c.height[2] == 0.0);
  // Near the axis (r < 1 mm): the band and the edge's rise over the first two bins.
  CHECK(c.central_height == Approx(band + slope * dx).margin(1e-9));
  CHECK(c.effective_height == Approx(5e-3 + slope * dx).margin(1e-9));
  // The order of the points does not matter.
  const std::vector<Vec3> xs(x.rbegin(), x.rend());
  const std::vector<int> ls(leaf.rbegin(), leaf.rend());
  const auto d = coaptation_stats(xs, ls, 3, Vec3::Zero(), Vec3::UnitY(), 1.5 * dx, 2 * dx, dx);
  CHECK(d.height == c.height);
  CHECK(d.central_height == c.central_height);
}

TEST_CASE("probes for the valve metrics: stress percentile and coaptation of the closed aortic valve",
          "[physiology][long]") {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);
  CHECK(percentile_nearest_rank(v, 95.0) == 95.0);
  CHECK(percentile_nearest_rank({3.0}, 95.0) == 3.0);
  CHECK(percentile_nearest_rank({}, 95.0) == 0.0);

  // The closed valve of aortic_root.json at t = 0: the three leaflets meet along all three coaptation lines,
  // in a band more than a spacing high, and at the centre, below the commissures.
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
    CHECK(values[2 * p] > s.spacing);                     // the sheets meet along a band (1.46 mm at stop 56)
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
  // The largest density error per cycle, from diagnostics.csv (issue 17 item 3).
  const CsvTable diag = read_csv(out / "diagnostics.csv");
  double largest = 0.0;
  for (const auto& row : diag.rows)
    if (row[diag.column("time")] <= 0.06 + 1e-9)
      largest = std::max(largest, row[diag.column("max_density_error")]);
  REQUIRE(cycles.column("max_density_error_pct") >= 0);
  CHECK(cycles.rows[0][cycles.column("max_density_error_pct")] == Approx(100.0 * largest));
  CHECK(largest > 0.0);
  // The volume check's range per cycle (fluid/volume_check.hpp), from the same file: in this 2 mm tube
  // (radius 2.5 spacings) no fluid particle's support holds only fluid, so every row is NaN and so are the
  // cycle's (written empty); the values are checked on synthetic signals ("... density error per cycle").
  for (const auto& row : diag.rows) CHECK(std::isnan(row[diag.column("volume_ratio")]));
  CHECK(std::isnan(cycles.rows[0][cycles.column("volume_ratio_min")]));
  CHECK(std::isnan(cycles.rows[0][cycles.column("volume_ratio_max")]));
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
  // 0 mmHg is the fluid's rest pressure by default (cycle.pressure_zero: tube_flow's background_pressure,
  // 200 Pa): the end-diastolic aortic pressure is the outlet probe's last row less 200 Pa.
  CHECK(c["pressure_zero_Pa"].get<double>() == 200.0);
  {
    const CsvTable probes = read_csv(out / "probes.csv");
    const auto& last = probes.rows.back();
    REQUIRE(last[probes.column("time")] == Approx(0.12));
    CHECK(cycles.rows[1][cycles.column("aortic_end_diastolic_mmHg")] ==
          Approx((last[probes.column("p_out")] - 200.0) / kPaPerMmHg).epsilon(1e-9));
  }

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
  // --remeasure: the cycles measured again from probes.csv with the scene run.json records. With the
  // recorded cycle.pressure_zero set to 0 the end-diastolic aortic pressure reads 200 Pa (1.50 mmHg) higher
  // and the stroke volume is unchanged; run.json follows.
  {
    const CsvTable before = read_csv(out / "cycles.csv");
    nlohmann::json recorded = nlohmann::json::parse(slurp(out / "run.json"));
    recorded["scene"]["cycle"]["pressure_zero"] = 0.0;
    std::ofstream(out / "run.json") << recorded.dump(2);
    std::string printed;
    REQUIRE(run_cli("plot " + out.string() + " --remeasure", err, &printed) == 0);
    CHECK(printed.find("cycle 1 [0.06, 0.12] s: SV") != std::string::npos);
    const CsvTable after = read_csv(out / "cycles.csv");
    REQUIRE(after.rows.size() == 2);
    const int edp = after.column("aortic_end_diastolic_mmHg"), sv = after.column("stroke_volume_ml");
    for (std::size_t r = 0; r < 2; ++r) {
      CHECK(after.rows[r][edp] == Approx(before.rows[r][edp] + 200.0 / kPaPerMmHg).epsilon(1e-9));
      CHECK(after.rows[r][sv] == before.rows[r][sv]);
    }
    const nlohmann::json rerun = nlohmann::json::parse(slurp(out / "run.json"));
    CHECK(rerun["cycles"]["pressure_zero_Pa"].get<double>() == 0.0);
    CHECK(rerun["cycles"]["metrics"]["aortic_end_diastolic_mmHg"].get<double>() ==
          Approx(after.rows[1][edp]));
    CHECK(run_cli("plot " + out.string() + " --again", err) == 2);
    CHECK(err.find("unknown option '--again'") != std::string::npos);
  }
  // A probes.csv without the columns the cycle block names: exit 2 naming the key and the column.
  { std::ofstream(out / "probes.csv") << "time,q_mid\n0,0\n0.06,0\n"; }
  CHECK(run_cli("plot " + out.string(), err) == 2);
  CHECK(err.find("cycle.lv_pressure") != std::string::npos);
  CHECK(run_cli("plot " + (dir / "missing").string(), err) == 2);
  CHECK(err.find("no such folder") != std::string::npos);
  // A run stopped before its first cycle ends (--end-time; the same for exit 3 or an interrupted run): its
  // run.json records time.end = 0.03 s, short of the two cycles the block asks for, which the scene loader
  // refuses. The plot is made as far as the run got, with no cycle metrics (until stop 45 it exited 2 after
  // the run's own warning had said to make it with `aortasph plot`).
  const fs::path part = dir / "part";
  REQUIRE(run_cli("run " + scene.string() + " --out " + part.string() +
                      " --end-time 0.03 --threads 1 --no-render --quiet",
                  err) == 0);
  CHECK(read_csv(part / "cycles.csv").rows.empty());
  CHECK(fs::is_regular_file(part / "figures" / "wiggers.png"));
  fs::remove(part / "figures" / "wiggers.png");
  REQUIRE(run_cli("plot " + part.string(), err) == 0);
  CHECK(slurp(part / "figures" / "wiggers.png").substr(1, 3) == "PNG");
  // A run stopped by the watchdog (exit 3: a density error limit of 4 %, which this tube passes at about
  // 9 ms, after a few output rows; 0.6 % at t = 0) writes cycles.csv too, so that its plot can be made (until
  // stop 45 cycles.csv was missing and `aortasph plot` refused the folder).
  const fs::path blew = dir / "blew";
  REQUIRE(run_cli("run " + scene.string() + " --out " + blew.string() +
                      " --set time.max_density_error=0.04 --threads 1 --no-render --quiet",
                  err) == 3);
  CHECK(read_csv(blew / "probes.csv").rows.size() >= 2);
  CHECK(read_csv(blew / "cycles.csv").rows.empty());
  REQUIRE(run_cli("plot " + blew.string(), err) == 0);
  CHECK(slurp(blew / "figures" / "wiggers.png").substr(1, 3) == "PNG");
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
      {"pressure_zero", "rest", "cycle.pressure_zero: expected a number"},
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
  // The jet's max_speed probe (the sixth) with a smoothed flag that is not a boolean.
  const fs::path scene = tube_cycle_scene(dir, good_cycle());
  nlohmann::json j = nlohmann::json::parse(slurp(scene));
  REQUIRE(j["probes"][5]["name"] == "jet");
  j["probes"][5]["smoothed"] = "yes";
  std::ofstream(scene) << j.dump(1);
  CHECK(run_cli("check " + scene.string(), err) == 2);
  CHECK(err.find("probes[5].smoothed: expected true or false") != std::string::npos);
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

TEST_CASE("valve metrics: gaps at peak diastolic load, stress per cusp with its place, leaflet-wall distance",
          "[physiology]") {
  // The synthetic cycle, with a 5 mmHg bump of the diastolic load peaking at 0.5 s: the gaps are read there.
  CycleSignals s = synthetic({400e-6}, {80.0});
  const std::size_t n = s.t.size();
  s.gap_commissural.assign(3, {});
  s.cusp_stress_max.assign(2, {});
  s.cusp_stress_p95.assign(2, {});
  s.cusp_peak_height.assign(2, {});
  s.cusp_peak_s.assign(2, {});
  s.wall_min_cusp.assign(2, {});
  for (std::size_t i = 0; i < n; ++i) {
    const double t = s.t[i];
    s.lv_pressure[i] -= 5 * kPaPerMmHg * std::max(0.0, 1.0 - std::abs(t - 0.5) / 0.05);
    s.gap_central.push_back(1e-6 * t);  // 1 mm^2 per s
    for (int c = 0; c < 3; ++c) s.gap_commissural[c].push_back(1e-7 * (c + 1) * t);
    // Cusp 0: stress rising linearly through the cycle (its peak in each phase at the phase's last sample);
    // cusp 1: a spike of 200 kPa at 0.1 s (systole) and 0.6 s (diastole). The place follows the time.
    s.cusp_stress_max[0].push_back(1e5 * t);
    s.cusp_stress_p95[0].push_back(0.5e5 * t);
    const bool spike = std::abs(t - 0.1) < 1e-9 || std::abs(t - 0.6) < 1e-9;
    s.cusp_stress_max[1].push_back(spike ? 2e5 : 1e3);
    s.cusp_stress_p95[1].push_back(spike ? 1e5 : 1e3);
    for (int c = 0; c < 2; ++c) {
      s.cusp_peak_height[c].push_back(0.01 * t);
      s.cusp_peak_s[c].push_back(t);
    }
    // Leaflet-wall distance: 5 mm, dipping to 1 mm at 0.2 s (systole) and to 0.5 mm at 0.7 s (diastole,
    // not counted); leaflet 1 stays at 3 mm.
    const double d = 0.005 - 0.004 * std::max(0.0, 1.0 - std::abs(t - 0.2) / 0.02) -
                     0.0045 * std::max(0.0, 1.0 - std::abs(t - 0.7) / 0.02);
    s.wall_min.push_back(d);
    s.wall_min_cusp[0].push_back(d);
    s.wall_min_cusp[1].push_back(0.003);
  }
  CycleOptions o;
  o.period = 0.8;
  const CycleMetrics m = all_cycle_metrics(s, o).at(0);
  CHECK(m.peak_load_time_ms == Approx(500.0).margin(1e-9));
  CHECK(m.central_gap_area_mm2 == Approx(0.5).epsilon(1e-9));
  REQUIRE(m.commissural_gap_area_mm2_per.size() == 3);
  for (int c = 0; c < 3; ++c)
    CHECK(m.commissural_gap_area_mm2_per[c] == Approx(0.05 * (c + 1)).epsilon(1e-9));
  CHECK(m.commissural_gap_area_mm2 == Approx(0.3).epsilon(1e-9));
  // Forward flow is [0, 0.3] s, closed from 0.336 s to the end (0.8 s).
  REQUIRE(m.cusp_systole.size() == 2);
  CHECK(m.cusp_systole[0].peak_kPa == Approx(30.0).epsilon(1e-6));
  CHECK(m.cusp_systole[0].p95_kPa == Approx(15.0).epsilon(1e-6));
  CHECK(m.cusp_systole[0].peak_height_mm == Approx(3.0).epsilon(1e-6));
  CHECK(m.cusp_diastole[0].peak_kPa == Approx(80.0).epsilon(1e-6));
  CHECK(m.cusp_diastole[0].peak_s == Approx(0.8).epsilon(1e-6));
  CHECK(m.cusp_systole[1].peak_kPa == Approx(200.0).epsilon(1e-9));
  CHECK(m.cusp_systole[1].peak_s == Approx(0.1).epsilon(1e-9));
  CHECK(m.cusp_systole[1].peak_height_mm == Approx(1.0).epsilon(1e-9));
  CHECK(m.cusp_diastole[1].peak_kPa == Approx(200.0).epsilon(1e-9));
  CHECK(m.cusp_diastole[1].p95_kPa == Approx(100.0).epsilon(1e-9));
  CHECK(m.cusp_diastole[1].peak_s == Approx(0.6).epsilon(1e-9));
  CHECK(m.leaflet_wall_min_systole_mm == Approx(1.0).epsilon(1e-9));
  REQUIRE(m.leaflet_wall_min_systole_mm_per.size() == 2);
  CHECK(m.leaflet_wall_min_systole_mm_per[0] == Approx(1.0).epsilon(1e-9));
  CHECK(m.leaflet_wall_min_systole_mm_per[1] == Approx(3.0).epsilon(1e-9));
  // The columns, in cycles.csv.
  const auto table = metric_table(m);
  auto value = [&](const std::string& name) {
    for (const auto& [k, v] : table)
      if (k == name) return v;
    FAIL("no column " << name);
    return 0.0;
  };
  CHECK(value("commissural_gap_area_c2_mm2") == Approx(0.15).epsilon(1e-9));
  CHECK(value("stress_diastole_peak_c1_s") == Approx(0.6).epsilon(1e-9));
  CHECK(value("leaflet_wall_min_systole_c1_mm") == Approx(3.0).epsilon(1e-9));
  // Without the probes: NaN, and no per-cusp columns.
  const CycleMetrics bare = all_cycle_metrics(synthetic({400e-6}, {80.0}), o).at(0);
  CHECK(std::isnan(bare.central_gap_area_mm2));
  CHECK(std::isnan(bare.leaflet_wall_min_systole_mm));
  CHECK(bare.cusp_systole.empty());
  CHECK(metric_table(bare).size() == table.size() - 3 - 2 * 2 * 4 - 2);
}

TEST_CASE("gap_area: the open area split into the centre and the commissures", "[physiology]") {
  // A disc of radius 10 mm covered by a square lattice of particles (0.5 mm) except two holes: a central one
  // (radius 2 mm) and one of radius 1.5 mm at 6 mm from the centre towards commissure 1 (of three at 90,
  // 210 and 330 degrees in the disc's plane). Central radius 3.33 mm. Each hole reads open inside its edge
  // less the cover radius 0.75 dx.
  const double dx = 0.0005, R = 0.01, rc = R / 3.0;
  const Vec3 centre(0, 0, 0), normal(0, 1, 0);
  // orifice_area's frame for normal +y (sim/physiology/orifice.cpp): u = x-hat x n, v = n x u.
  const Vec3 u = Vec3::UnitX().cross(normal).normalized(), v = normal.cross(u);
  auto dir = [&](double deg) { return Vec3(std::cos(deg * kPi / 180) * u + std::sin(deg * kPi / 180) * v); };
  const std::vector<Vec3> comm = {0.012 * dir(90), 0.012 * dir(210), 0.012 * dir(330)};
  const Vec3 hole2 = 0.006 * dir(210);
  std::vector<Vec3> pts;
  for (int i = -24; i <= 24; ++i)
    for (int j = -24; j <= 24; ++j) {
      const Vec3 p = (i * dx) * u + (j * dx) * v;
      if (p.norm() < 0.002 || (p - hole2).norm() < 0.0015) continue;
      pts.push_back(p + Vec3(0, 0.0003 * ((i + j) % 3), 0));  // off the plane: projected
    }
  const OrificeRegions r = orifice_regions(pts, dx, centre, normal, R, rc, comm);
  INFO("total " << r.total * 1e6 << " mm2, central " << r.central * 1e6 << ", commissural "
                << r.commissural[0] * 1e6 << " " << r.commissural[1] * 1e6 << " " << r.commissural[2] * 1e6);
  CHECK(r.total == orifice_area(pts, dx, centre, normal, R));
  CHECK(r.central + r.commissural[0] + r.commissural[1] + r.commissural[2] == Approx(r.total).epsilon(1e-12));
  // The holes' open discs: radius minus the cover radius, minus up to one lattice step for where the lattice
  // points fall (hole 1: the farthest removed point lies within 2 mm; its neighbours cover beyond).
  const double cover = kOrificeCoverRadius * dx;
  CHECK(r.central > kPi * std::pow(0.002 - cover - dx, 2));
  CHECK(r.central < kPi * std::pow(0.002 - cover + dx, 2));
  CHECK(r.commissural[1] > kPi * std::pow(0.0015 - cover - dx, 2));
  CHECK(r.commissural[1] < kPi * std::pow(0.0015 - cover + dx, 2));
  CHECK(r.commissural[0] == 0.0);
  CHECK(r.commissural[2] == 0.0);
  // Without commissures everything open is central; the ring outside the lattice (beyond 12 mm) is not on
  // the disc.
  const OrificeRegions none = orifice_regions(pts, dx, centre, normal, R, rc, {});
  CHECK(none.central == r.total);
}

namespace {

Material rubber_material() {
  Material m;
  m.name = "rubber";
  m.type = MaterialType::Elastic;
  m.density = 1000.0;
  m.youngs_modulus = 2e4;
  m.poisson_ratio = 0.3;
  return m;
}

Body box_body(const std::string& name, int material, const Box& box) {
  Body b;
  b.name = name;
  b.material = material;
  b.shape.kind = ShapeKind::Box;
  b.shape.box = box;
  return b;
}

}  // namespace

TEST_CASE("wall_distance probe: a plate falling onto a wall, the attached strip left out, the cap",
          "[physiology]") {
  // A free elastic plate 8 mm above a wall falls under gravity: its distance to the wall shrinks by g t^2 / 2
  // (no stress in uniform free fall). A clamped strip 1 mm from the wall (within `exclude` at t = 0: an
  // attachment) is left out: the minimum is the plate's. A second probe capped at 4 mm reads 4 mm. One
  // thread: a few hundred particles, too few to share.
  struct OneThread {
    int before = max_threads();
    OneThread() { set_threads(1); }
    ~OneThread() { set_threads(before); }
  } one_thread;
  Scene s;
  s.name = "fall";
  s.spacing = 0.002;
  s.gravity = Vec3(0, -9.81, 0);
  s.domain = {Vec3(-0.03, -0.02, -0.03), Vec3(0.03, 0.03, 0.03)};
  Material wall;
  wall.name = "wall";
  wall.type = MaterialType::Wall;
  s.materials = {rubber_material(), wall};
  s.bodies = {box_body("floor", 1, {Vec3(-0.02, -0.006, -0.02), Vec3(0.02, 0.0, 0.02)}),
              box_body("plate", 0, {Vec3(-0.02, 0.008, -0.012), Vec3(0.0, 0.012, 0.008)}),
              box_body("strip", 0, {Vec3(-0.02, 0.0, 0.016), Vec3(0.02, 0.002, 0.02)})};
  s.bodies[2].fixed = Box{Vec3(-0.03, -0.01, 0.015), Vec3(0.03, 0.01, 0.03)};
  Probe p;
  p.name = "wd";
  p.type = ProbeType::WallDistance;
  p.bodies = {1, 2};
  p.walls = {0};
  p.exclude = 3 * s.spacing;
  p.reach = 0.02;
  Probe capped = p;
  capped.name = "wd4";
  capped.reach = 0.004;
  s.probes = {p, capped};
  World w(s);
  const ProbeSet probes(s, w);
  REQUIRE(probes.columns() ==
          std::vector<std::string>{"wd.min", "wd.min_0", "wd.min_1", "wd4.min", "wd4.min_0", "wd4.min_1"});
  // Brute force over the plate's particles (the strip's are all within exclude of the wall at t = 0).
  auto brute = [&]() {
    const Particles& P = w.particles();
    double best = 1e9;
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == 1)
        for (std::size_t j = 0; j < P.size(); ++j)
          if (P.body[j] == 0) best = std::min(best, (P.x[i] - P.x[j]).norm());
    return best;
  };
  const auto v0 = probes.measure(w);
  const double d0 = brute();
  INFO("t = 0: " << v0[0] * 1e3 << " mm (brute force " << d0 * 1e3 << " mm)");
  CHECK(v0[0] == Approx(d0).epsilon(1e-12));
  CHECK(v0[1] == v0[0]);
  CHECK(std::isnan(v0[2]));  // the strip: attached, left out
  CHECK(d0 > 0.006);
  CHECK(v0[3] == Approx(0.004).epsilon(1e-12));  // capped
  const double t = 0.02;
  w.advance_to(t, [] { return true; });
  const auto v1 = probes.measure(w);
  INFO("t = " << w.time() << ": " << v1[0] * 1e3 << " mm");
  CHECK(v1[0] == Approx(brute()).epsilon(1e-12));
  CHECK(d0 - v1[0] == Approx(0.5 * 9.81 * w.time() * w.time()).epsilon(0.03));
}

TEST_CASE("stress probe per body: each beam's peak, 95th percentile and the peak's place", "[physiology]") {
  // Two clamped rubber beams sagging under gravity, 80 and 40 mm long: per body, the max and p95 of its own
  // particles, and the reference height and cusp fraction of the particle carrying the max.
  struct OneThread {
    int before = max_threads();
    OneThread() { set_threads(1); }
    ~OneThread() { set_threads(before); }
  } one_thread;
  Scene s;
  s.name = "beams";
  s.spacing = 0.005;
  s.gravity = Vec3(0, -9.81, 0);
  s.domain = {Vec3(-0.02, -0.05, -0.02), Vec3(0.1, 0.03, 0.06)};
  s.materials = {rubber_material()};
  s.bodies = {box_body("long", 0, {Vec3(-0.01, 0, 0), Vec3(0.08, 0.01, 0.01)}),
              box_body("short", 0, {Vec3(-0.01, 0, 0.03), Vec3(0.04, 0.01, 0.04)})};
  for (Body& b : s.bodies) b.fixed = Box{Vec3(-0.02, -0.05, -0.02), Vec3(0, 0.03, 0.06)};
  Probe p;
  p.name = "st";
  p.type = ProbeType::Stress;
  p.bodies = {0, 1};
  p.per_body = true;
  p.point = Vec3(0.1, 0.0, 0.02);  // the "axis": the vertical line x = 0.1, z = 0.02
  p.normal = Vec3::UnitY();
  s.probes = {p};
  World w(s);
  const ProbeSet probes(s, w);
  REQUIRE(probes.columns().size() == 4 + 2 * 4);
  CHECK(probes.columns()[4] == "st.0.max");
  CHECK(probes.columns()[11] == "st.1.max_s");
  w.advance_to(0.02, [] { return true; });
  const auto v = probes.measure(w);
  const Solids& S = w.solids();
  const Particles& P = w.particles();
  const Vec3 u = Vec3::UnitX().cross(p.normal).normalized(), vv = p.normal.cross(u);
  auto angle = [&](const Vec3& x) { return std::atan2((x - p.point).dot(vv), (x - p.point).dot(u)); };
  for (int b = 0; b < 2; ++b) {
    std::vector<double> vm;
    double best = -1, lo = 1e9, hi = -1e9;
    Vec3 where = Vec3::Zero();
    for (std::size_t k = 0; k < S.size(); ++k)
      if (P.body[S.at(k)] == b) {
        vm.push_back(S.von_mises(k));
        if (S.von_mises(k) > best) {
          best = S.von_mises(k);
          where = P.x0[S.at(k)];
        }
      }
    for (std::size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == b) {
        lo = std::min(lo, angle(P.x0[i]));  // the beams lie on one side of the axis: no wrap
        hi = std::max(hi, angle(P.x0[i]));
      }
    INFO("body " << b << ": max " << v[4 + 4 * b] << " Pa at height " << v[6 + 4 * b] << " m, s "
                 << v[7 + 4 * b]);
    CHECK(v[4 + 4 * b] == best);
    CHECK(v[5 + 4 * b] == percentile_nearest_rank(vm, 95.0));
    CHECK(v[6 + 4 * b] == Approx(where.y()).margin(1e-15));
    CHECK(v[7 + 4 * b] == Approx((angle(where) - lo) / (hi - lo)).epsilon(1e-9));
    CHECK(v[7 + 4 * b] >= 0.0);
    CHECK(v[7 + 4 * b] <= 1.0);
  }
  // The overall max is the larger of the two bodies'.
  CHECK(v[0] == std::max(v[4], v[8]));
}

TEST_CASE("gap_area, wall_distance and per-cusp stress on the aortic roots: volumetric and shell leaflets",
          "[physiology][long]") {
  // The closed valves at t = 0 of scenes/aortic_valve_cycle.json (volumetric leaflets; the probes as shipped,
  // with the loader's defaults from the root) and scenes/aortic_root_shell.json (shell leaflets; the same
  // probes added): the gap regions add up to the orifice area, every leaflet keeps particles beyond `exclude`
  // from the wall (the distance is then at least `exclude`), and the peak stress's place lies on its cusp.
  for (const std::string name : {"aortic_valve_cycle", "aortic_root_shell"}) {
    INFO(name);
    std::ifstream in(std::string(AORTASPH_TEST_DIR) + "/../scenes/" + name + ".json");
    nlohmann::json j = nlohmann::json::parse(in);
    if (name == "aortic_root_shell") {
      const nlohmann::json leaf = {"leaflet0", "leaflet1", "leaflet2"};
      for (auto& p : j["probes"])
        if (p["name"] == "leaflet_stress") p["per_body"] = true;
      j["probes"].push_back({{"name", "gaps"}, {"type", "gap_area"}, {"bodies", leaf}});
      j["probes"].push_back(
          {{"name", "leaflet_wall"}, {"type", "wall_distance"}, {"bodies", leaf}, {"walls", {"root"}}});
    }
    j.erase("render");
    const Scene s = load_scene_json(j, {}).scene;
    const World w(s);
    const ProbeSet probes(s, w);
    const auto v = probes.measure(w);
    auto col = [&](const std::string& c) {
      const auto& cols = probes.columns();
      const auto it = std::find(cols.begin(), cols.end(), c);
      REQUIRE(it != cols.end());
      return v[static_cast<std::size_t>(it - cols.begin())];
    };
    const double dx = s.spacing;
    INFO("orifice " << col("orifice") * 1e6 << " mm2, gaps central " << col("gaps.central") * 1e6
                    << ", commissural " << col("gaps.commissural") * 1e6 << "; wall "
                    << col("leaflet_wall.min") * 1e3 << " mm");
    CHECK(col("gaps.total") == col("orifice"));
    CHECK(col("gaps.central") + col("gaps.commissural") == Approx(col("gaps.total")).epsilon(1e-12));
    CHECK(col("gaps.commissural_0") + col("gaps.commissural_1") + col("gaps.commissural_2") ==
          Approx(col("gaps.commissural")).epsilon(1e-12));
    const AorticRoot root(s.bodies[static_cast<std::size_t>(s.probes.back().bodies[0])].shape.aortic);
    for (int k = 0; k < 3; ++k) {
      const std::string K = std::to_string(k);
      const double d = col("leaflet_wall.min_" + K);
      CHECK(d >= 3 * dx - 1e-12);  // at t = 0 the kept particles are at least `exclude` from the wall
      CHECK(d <= 8 * dx);
      const double s_k = col("leaflet_stress." + K + ".max_s"),
                   h = col("leaflet_stress." + K + ".max_height");
      CHECK(s_k >= 0.0);
      CHECK(s_k <= 1.0);
      CHECK(h >= root.leaflet_lowest() - dx);
      CHECK(h <= root.params().commissure_height + dx);
      CHECK(col("leaflet_stress." + K + ".p95") <= col("leaflet_stress." + K + ".max"));
    }
    CHECK(col("leaflet_wall.min") ==
          std::min({col("leaflet_wall.min_0"), col("leaflet_wall.min_1"), col("leaflet_wall.min_2")}));
  }
}

TEST_CASE("gap_area, wall_distance and per_body probes: bad input exits 2 naming the JSON path",
          "[physiology][bad-input]") {
  // On the tube scene (no aortic root: nothing to default from), each probe appended after the tube's six.
  const fs::path dir = scratch("valve_probe_bad");
  const nlohmann::json disc = {{"point", {0, 0, 0}}, {"normal", {0, 1, 0}}};
  auto gap = [&](const nlohmann::json& more) {
    nlohmann::json p = {{"name", "g"}, {"type", "gap_area"}, {"bodies", {"tube"}}};
    p.update(disc);
    p.update(more);
    return p;
  };
  auto wall = [](const nlohmann::json& more) {
    nlohmann::json p = {{"name", "w"}, {"type", "wall_distance"}, {"bodies", {"blood"}}, {"walls", {"tube"}}};
    p.update(more);
    return p;
  };
  struct Case {
    nlohmann::json probe;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {gap({{"commissures", {{0.01, 0, 0}, {-0.01, 0, 0}}}}), "probes[6].radius: missing"},
      {gap({{"radius", 0.01}}),
       "probes[6].commissures: required unless the bodies are untransformed aortic_root"},
      {gap({{"radius", 0.01}, {"commissures", {{0.01, 0, 0}, {0, 0.02, 0}}}}),
       "probes[6].commissures[1]: on the axis"},
      {gap({{"radius", 0.01}, {"commissures", {{0.01, 0, 0}}}}),
       "probes[6].commissures: expected a list of 2 to 16"},
      {gap({{"radius", 0.01}, {"central_radius", 0.01}, {"commissures", {{0.01, 0, 0}, {-0.01, 0, 0}}}}),
       "probes[6].central_radius: must be smaller than the radius"},
      {wall({{"walls", {"blood"}}}), "probes[6].walls[0]: body 'blood' is also in 'bodies'"},
      {wall({{"reach", 1.0}}), "probes[6].reach: at most 50 spacings"},
      {wall({{"walls", nlohmann::json::array()}}), "probes[6].walls: expected at least one body"},
      {wall({{"exclude", -1.0}}), "probes[6].exclude"},
      {{{"name", "c"},
        {"type", "coaptation"},
        {"bodies", {"blood", "tube"}},
        {"point", {0, 0, 0}},
        {"normal", {0, 1, 0}},
        {"per_leaflet", 3}},
       "probes[6].per_leaflet"},
  };
  for (const Case& c : cases) {
    std::ifstream in(tube_cycle_scene(dir, good_cycle()));
    nlohmann::json s = nlohmann::json::parse(in);
    REQUIRE(s["probes"].size() == 6);
    s["probes"].push_back(c.probe);
    const fs::path file = dir / "probe_bad.json";
    std::ofstream(file) << s.dump(1);
    std::string err;
    INFO(c.probe.dump());
    CHECK(aortasph::test::run_cli("check " + file.string(), err) == 2);
    INFO(err);
    CHECK(err.find(c.expect) != std::string::npos);
  }
  // The cycle block's keys name probes of their own type.
  nlohmann::json cycle = good_cycle();
  cycle["gap_area"] = "q_mid";
  cycle["wall_distance"] = "q_mid";
  std::string err;
  CHECK(run_cli("check " + tube_cycle_scene(dir, cycle).string(), err) == 2);
  CHECK(err.find("cycle.gap_area: probe 'q_mid' is not a gap_area probe") != std::string::npos);
}

TEST_CASE("valve metrics: acoustic noise of the LV pressure and the largest density error per cycle",
          "[physiology]") {
  // The noise: RMS about a 10 ms centred running mean. A ramp (which the running mean follows exactly) plus
  // a 200 Hz sine of 200 Pa sampled every 0.5 ms: each window is 21 samples, two periods and one more sample
  // of the sample's own phase, so the deviation is 20/21 of the sine: RMS 134.7 Pa.
  std::vector<double> t, p;
  for (int i = 0; i <= 200; ++i) {
    t.push_back(i * 5e-4);
    p.push_back(5000.0 + 2e4 * t.back() + 200.0 * std::sin(2 * kPi * 200.0 * t.back()));
  }
  const double rms = 200.0 / std::sqrt(2.0) * 20.0 / 21.0;
  CHECK(running_mean_rms(t, p, 0.02, 0.08, 0.01, 0.001) == Approx(rms).epsilon(0.01));
  // Only samples whose whole window lies in the signal count: over [0, 0.1] the same.
  CHECK(running_mean_rms(t, p, 0.0, 0.1, 0.01, 0.001) == Approx(rms).epsilon(0.01));
  // Samples 2 ms apart, or a gap of 2 ms within reach of the window: not measurable.
  std::vector<double> t2, p2;
  for (std::size_t i = 0; i < t.size(); i += 4) t2.push_back(t[i]), p2.push_back(p[i]);
  CHECK(std::isnan(running_mean_rms(t2, p2, 0.02, 0.08, 0.01, 0.001)));
  std::vector<double> tg = t, pg = p;
  tg.erase(tg.begin() + 100, tg.begin() + 103);
  pg.erase(pg.begin() + 100, pg.begin() + 103);
  CHECK(std::isnan(running_mean_rms(tg, pg, 0.02, 0.08, 0.01, 0.001)));
  CHECK(std::isfinite(running_mean_rms(tg, pg, 0.02, 0.04, 0.01, 0.001)));  // the gap is out of reach

  // In a cycle: the noise over the forward flow (the synthetic cycle's 0-0.3 s), and the largest density
  // error of the cycle (a 1.2 % bump at 0.5 s).
  CycleOptions o;
  o.period = 0.8;
  CycleSignals s = synthetic({400e-6}, {80.0});
  for (const double x : s.t)
    s.density_error.push_back(0.004 + 0.008 * std::exp(-std::pow((x - 0.5) / 0.01, 2)));
  // The volume check: 0.997 with a dip to 0.947 at 0.2 s and a bump to 1.017 at 0.6 s.
  for (const double x : s.t)
    s.volume_ratio.push_back(0.997 - 0.05 * std::exp(-std::pow((x - 0.2) / 0.01, 2)) +
                             0.02 * std::exp(-std::pow((x - 0.6) / 0.01, 2)));
  const CycleMetrics quiet = all_cycle_metrics(s, o).at(0);
  CHECK(quiet.volume_ratio_min == Approx(0.947).epsilon(1e-4));
  CHECK(quiet.volume_ratio_max == Approx(1.017).epsilon(1e-4));
  // Noise of +-300 Pa alternating sample by sample over 0.05-0.25 s: a window of 11 samples holds 5 of the
  // sample's sign and 6 of the other, so the deviation is 300 (1 + 1/11) Pa.
  int noisy_samples = 0, counted = 0;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    if (s.t[i] > 0.05 && s.t[i] < 0.25) s.lv_pressure[i] += (i % 2 ? 300.0 : -300.0), ++noisy_samples;
    if (s.t[i] >= 0.005 - 1e-9 && s.t[i] <= 0.3 + 1e-9) ++counted;
  }
  const CycleMetrics noisy = all_cycle_metrics(s, o).at(0);
  INFO("LV noise: quiet " << quiet.lv_noise_Pa << " Pa, with +-300 Pa over 0.05-0.25 s " << noisy.lv_noise_Pa
                          << " Pa");
  CHECK(quiet.max_density_error_pct == Approx(1.2).epsilon(1e-3));
  // The quiet cycle's LV pressure is smooth but for the end of ejection (10 -> -80 mmHg from 0.3 s), which
  // the last windows reach; the noise adds its mean square over its share of the counted samples (those from
  // 5 ms, where a whole window starts, to the end of forward flow at 0.3 s).
  CHECK(quiet.lv_noise_Pa < 50.0);
  const double dev = 300.0 * 12.0 / 11.0;
  const double expected = std::sqrt(quiet.lv_noise_Pa * quiet.lv_noise_Pa +
                                    dev * dev * noisy_samples / static_cast<double>(counted));
  CHECK(noisy.lv_noise_Pa == Approx(expected).epsilon(0.03));
  // No density error column, or samples 2 ms apart: NaN (written empty).
  CycleSignals coarse = synthetic({400e-6}, {80.0});
  CycleSignals thin;
  for (std::size_t i = 0; i < coarse.t.size(); i += 2) {
    thin.t.push_back(coarse.t[i]);
    thin.valve_flow.push_back(coarse.valve_flow[i]);
    thin.lv_pressure.push_back(coarse.lv_pressure[i]);
    thin.aortic_pressure.push_back(coarse.aortic_pressure[i]);
  }
  const CycleMetrics m2 = all_cycle_metrics(thin, o).at(0);
  CHECK(std::isnan(m2.max_density_error_pct));
  CHECK(std::isnan(m2.volume_ratio_min));
  CHECK(std::isnan(m2.volume_ratio_max));
  CHECK(std::isnan(m2.lv_noise_Pa));
  CHECK(std::isfinite(m2.stroke_volume_ml));
}

TEST_CASE("cycles.csv: before the first cycle completes, the header already has the scene's columns",
          "[physiology]") {
  // The physio scene's probes give per-pair coaptation, per-commissure gap and per-cusp stress and
  // wall-distance columns. Until stop 42 an unfinished run's cycles.csv had only the columns every scene has
  // (its header came from an empty metrics record), and the rest appeared when the first cycle completed.
  const fs::path file = fs::path(AORTASPH_TEST_DIR) / ".." / "scenes" / "aortic_valve_cycle_physio.json";
  const Scene s = load_scene(file, {}).scene;
  const fs::path out = scratch("cycles_header") / "cycles.csv";
  write_cycles_csv(out, {}, s);
  const CsvTable table = read_csv(out);
  CHECK(table.rows.empty());
  const std::vector<std::string>& header = table.header;
  CHECK(header == cycle_metric_names(s));
  for (const char* name : {"coaptation_height_0_1_mm", "coaptation_height_1_2_mm", "effective_height_c2_mm",
                           "commissural_gap_area_c0_mm2", "leaflet_wall_min_systole_c1_mm",
                           "stroke_volume_ml", "max_density_error_pct"}) {
    INFO(name);
    CHECK(std::find(header.begin(), header.end(), name) != header.end());
  }
  // More than the columns every scene has (the header of an empty metrics record, as before).
  CHECK(header.size() > metric_table(CycleMetrics{}).size());
}
