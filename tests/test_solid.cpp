// Elastic solids by Total-Lagrangian SPH (paper eqs. 14-18) with gradient correction, hourglass control and
// artificial viscosity: patch tests, wave speed, cantilever vibration, energy, large deformation, bad input.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>

#include "builders.hpp"
#include "parallel.hpp"
#include "probes.hpp"
#include "sim_errors.hpp"
#include "solid_tlsph.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

Material rubber(double E, double nu, double rho = 1000.0) {
  Material m;
  m.name = "rubber";
  m.type = MaterialType::Elastic;
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  return m;
}

// A block of nx x ny x nz elastic particles at spacing dx, set up by hand (reference = current).
Particles block(int nx, int ny, int nz, double dx) {
  Particles P;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const std::size_t n = P.size();
        P.resize(n + 1);
        P.x[n] = P.x0[n] = dx * Vec3(i + 0.5, j + 0.5, k + 0.5);
        P.kind[n] = Kind::Elastic;
        P.id[n] = static_cast<uint32_t>(n);
        P.m[n] = 1000.0 * dx * dx * dx;
      }
  return P;
}

double max_abs(const Mat3& M) {
  return M.cwiseAbs().maxCoeff();
}

// A scene with one elastic box body along x, clamped where x < 0, no gravity unless given.
Scene beam_scene(double length, double H, double W, double clamp, double dx, const Material& mat,
                 Vec3 gravity = Vec3::Zero()) {
  Scene s;
  s.name = "beam";
  s.spacing = dx;
  s.gravity = gravity;
  s.domain = {Vec3(-1, -1, -1), Vec3(2, 1, 1)};
  s.max_dt = 1e-3;
  s.materials = {mat};
  Body b = box_body("beam", 0, Vec3(-clamp, 0, 0), Vec3(length, H, W));
  if (clamp > 0.0) b.fixed = Box{Vec3(-1, -1, -1), Vec3(0, 1, 1)};
  s.bodies = {b};
  return s;
}

// Mean of a vector field component over the particles of a world with x0 in a slab |x0.x - x| < dx/2.
double mean_in_slab(const World& w, double x, double dx, auto&& value) {
  const Particles& P = w.particles();
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (std::abs(P.x0[i].x() - x) < 0.5 * dx) {
      sum += value(i);
      ++n;
    }
  return n ? sum / n : 0.0;
}

// First-mode shape of a clamped-free beam (Euler-Bernoulli), normalised to 1 at the tip: x from the clamp.
double mode1(double x, double L) {
  const double kL = 1.875104068711961, k = kL / L;
  const double M = std::sin(kL) + std::sinh(kL), N = std::cos(kL) + std::cosh(kL);
  auto f = [&](double s) {
    return M * (std::cos(k * s) - std::cosh(k * s)) - N * (std::sin(k * s) - std::sinh(k * s));
  };
  return f(x) / f(L);
}

struct Oscillation {
  double period = 0.0;  // mean time between upward zero crossings of the tip displacement [s]
  double decay = 0.0;   // mean relative amplitude loss per period
  int crossings = 0;
  double max_energy_drift = 0.0;  // max |E(t) / E(0) - 1|
};

// Runs a clamped beam given its first-mode velocity profile (tip speed v_tip, along y) for `periods` beam
// periods and measures its tip oscillation and energy.
Oscillation vibrate(World& w, double L, double v_tip, double t_end, double sample) {
  w.set_initial_velocity(0,
                         [&](const Vec3& x0) { return Vec3(0, v_tip * mode1(std::max(x0.x(), 0.0), L), 0); });
  const double dx = w.scene().spacing;
  const double x_tip = L - 0.5 * dx;
  Scene probe_scene = w.scene();
  probe_scene.probes = {Probe{}};
  probe_scene.probes[0].name = "e";
  probe_scene.probes[0].type = ProbeType::Energy;
  ProbeSet energy(probe_scene, w);
  const double e0 = energy.measure(w)[3];
  Oscillation o;
  double prev = 0.0, t_prev = 0.0, first_cross = -1, last_cross = -1;
  std::vector<double> peaks;
  double peak = 0.0;
  while (w.time() < t_end - 1e-12) {
    w.advance_to(std::min(t_end, w.time() + sample), [] { return true; });
    const double uy = mean_in_slab(
        w, x_tip, dx, [&](std::size_t i) { return w.particles().x[i].y() - w.particles().x0[i].y(); });
    const double e = energy.measure(w)[3];
    o.max_energy_drift = std::max(o.max_energy_drift, std::abs(e / e0 - 1.0));
    peak = std::max(peak, uy);
    // Upward zero crossing, interpolated linearly.
    if (prev < 0.0 && uy >= 0.0) {
      const double tc = t_prev + (w.time() - t_prev) * (-prev) / (uy - prev);
      if (first_cross < 0) first_cross = tc;
      last_cross = tc;
      ++o.crossings;
      peaks.push_back(peak);
      peak = 0.0;
    }
    prev = uy;
    t_prev = w.time();
  }
  if (o.crossings >= 2) o.period = (last_cross - first_cross) / (o.crossings - 1);
  // peaks[k] is the maximum between crossings k-1 and k; peaks[1..] are full periods.
  if (peaks.size() >= 3)
    o.decay = 1.0 - std::pow(peaks.back() / peaks[1], 1.0 / static_cast<double>(peaks.size() - 2));
  return o;
}

}  // namespace

TEST_CASE("TL-SPH patch tests: rigid motions give zero stress, a uniform stretch the analytic S and P",
          "[solid]") {
  const double dx = 0.01;
  Particles P = block(9, 9, 9, dx);
  const Material mat = rubber(1e6, 0.3);
  const CubicSpline K(1.3 * dx);
  Solids solid(P, {mat}, K, dx, {});
  REQUIRE(solid.size() == P.size());
  const SolidParams sp(mat);

  SECTION("translation") {
    for (std::size_t i = 0; i < P.size(); ++i) P.x[i] = P.x0[i] + Vec3(0.3, -0.2, 0.05);
    solid.update_stress(P);
    for (std::size_t s = 0; s < solid.size(); ++s) {
      CHECK(max_abs(solid.F(s) - Mat3::Identity()) < 1e-12);
      CHECK(max_abs(solid.PK1(s)) < 1e-9 * sp.E);
    }
  }
  SECTION("rotation") {
    const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    for (std::size_t i = 0; i < P.size(); ++i) P.x[i] = R * P.x0[i] + Vec3(0.1, 0.0, 0.0);
    solid.update_stress(P);
    double worst = 0;
    for (std::size_t s = 0; s < solid.size(); ++s) {
      CHECK(max_abs(solid.F(s) - R) < 1e-12);
      worst = std::max(worst, max_abs(solid.PK1(s)));
      CHECK(solid.von_mises(s) < 1e-9 * sp.E);
    }
    CHECK(worst < 1e-9 * sp.E);
    std::vector<Vec3> f(P.size(), Vec3::Zero());
    solid.add_forces(P, f);
    for (const Vec3& fi : f) CHECK(fi.norm() < 1e-9 * sp.E * dx * dx);
  }
  SECTION("uniform stretch, every particle including the surface") {
    const Mat3 Fa = Vec3(1.1, 0.95, 1.02).asDiagonal();
    for (std::size_t i = 0; i < P.size(); ++i) P.x[i] = Fa * P.x0[i];
    solid.update_stress(P);
    const Mat3 E = 0.5 * (Fa.transpose() * Fa - Mat3::Identity());
    const Mat3 S = sp.lambda * E.trace() * Mat3::Identity() + 2.0 * sp.mu * E;
    const Mat3 Pa = Fa * S;
    for (std::size_t s = 0; s < solid.size(); ++s) {
      CHECK(max_abs(solid.F(s) - Fa) < 1e-12);
      CHECK(max_abs(solid.PK1(s) - Pa) < 1e-9 * sp.E);
    }
    // The analytic values themselves: lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
    CHECK(sp.lambda == Approx(1e6 * 0.3 / (1.3 * 0.4)));
    CHECK(sp.mu == Approx(1e6 / 2.6));
    // A uniform stress is in equilibrium: the centre particle, whose neighbours all have full kernel
    // support, feels no net force (to round-off), while surface particles carry the traction.
    std::vector<Vec3> f(P.size(), Vec3::Zero());
    solid.add_forces(P, f);
    const std::size_t centre = 4 * 81 + 4 * 9 + 4;
    CHECK(f[centre].norm() < 1e-9 * sp.E * dx * dx);
    CHECK(f[0].norm() > 1e-3 * sp.E * dx * dx);
  }
}

TEST_CASE("TL-SPH neo-Hookean: rigid rotation stress-free, uniform stretch analytic, stiffens in compression",
          "[solid]") {
  const double dx = 0.01;
  Particles P = block(7, 7, 7, dx);
  Material mat = rubber(1e6, 0.3);
  mat.neo_hookean = true;
  const CubicSpline K(1.3 * dx);
  Solids solid(P, {mat}, K, dx, {});
  const SolidParams sp(mat);
  REQUIRE(sp.neo_hookean);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (std::size_t i = 0; i < P.size(); ++i) P.x[i] = R * P.x0[i];
  solid.update_stress(P);
  for (std::size_t s = 0; s < solid.size(); ++s) CHECK(max_abs(solid.PK1(s)) < 1e-9 * sp.E);

  const Mat3 Fa = Vec3(1.1, 0.95, 1.02).asDiagonal();
  for (std::size_t i = 0; i < P.size(); ++i) P.x[i] = Fa * P.x0[i];
  solid.update_stress(P);
  const double J = Fa.determinant();
  const Mat3 FinvT = Fa.inverse().transpose();
  const Mat3 Pa = sp.mu * (Fa - FinvT) + sp.lambda * std::log(J) * FinvT;
  for (std::size_t s = 0; s < solid.size(); ++s) CHECK(max_abs(solid.PK1(s) - Pa) < 1e-9 * sp.E);

  // Small strain: the same stress as Saint Venant-Kirchhoff (eq. 16) to first order.
  const Mat3 Fs = Vec3(1.0 + 1e-5, 1.0 - 2e-5, 1.0).asDiagonal();
  CHECK(max_abs(neo_hookean_stress(Fs, sp.lambda, sp.mu).P - svk_stress(Fs, sp.lambda, sp.mu).P) <
        1e-3 * max_abs(svk_stress(Fs, sp.lambda, sp.mu).P));
  // Uniaxial compression to a stretch of 0.4: SVK's axial stress has passed its peak (at 1/sqrt(3)) and
  // softens; neo-Hookean's keeps growing.
  auto axial = [&](double l, bool neo) {
    const Mat3 F = Vec3(l, 1.0, 1.0).asDiagonal();
    return neo ? neo_hookean_stress(F, sp.lambda, sp.mu).P(0, 0) : svk_stress(F, sp.lambda, sp.mu).P(0, 0);
  };
  CHECK(std::abs(axial(0.4, false)) < std::abs(axial(0.6, false)));
  CHECK(std::abs(axial(0.4, true)) > std::abs(axial(0.6, true)));
}

TEST_CASE("TL-SPH: internal forces conserve momentum and angular momentum", "[solid][conservation]") {
  const double dx = 0.01;
  Particles P = block(6, 5, 4, dx);
  const Material mat = rubber(1e6, 0.45);
  const CubicSpline K(1.3 * dx);
  Solids solid(P, {mat}, K, dx, {});
  // A random-looking but deterministic deformation and velocity field.
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double a = static_cast<double>(i);
    P.x[i] = P.x0[i] + 0.1 * dx * Vec3(std::sin(1.3 * a), std::cos(2.1 * a), std::sin(0.7 * a + 1));
    P.v[i] = Vec3(std::cos(0.3 * a), std::sin(1.7 * a), std::cos(2.9 * a));
  }
  solid.update_stress(P);
  std::vector<Vec3> f(P.size(), Vec3::Zero());
  solid.add_forces(P, f);
  Vec3 F = Vec3::Zero(), M = Vec3::Zero();
  double scale = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    F += f[i];
    M += P.x[i].cross(f[i]);
    scale += f[i].norm();
  }
  REQUIRE(scale > 0.0);
  CHECK(F.norm() < 1e-12 * scale);
  // eq. (18) and the stabilisers act along pairs or derive from a rotation-invariant energy.
  CHECK(M.norm() < 1e-10 * scale * 0.1);
}

TEST_CASE("TL-SPH: a velocity pulse in a thin bar travels at sqrt(E/rho) and inverts at a fixed end",
          "[solid][validation]") {
  // tests/data/elastic_wave_speeds_examples.csv, row oscillating_plate_GMS2001: E = 2 MPa, rho = 1000,
  // nu = 0.3975, c_bar = 44.7214 m/s (the bar speed: the P-wave speed 64.85 m/s needs lateral constraint).
  const double c_bar = 44.7214, dx = 0.01, L = 1.2, H = 0.04;
  const Material mat = rubber(2e6, 0.3975);
  Scene s = beam_scene(L, H, H, 0.0, dx, mat);
  s.bodies[0].fixed = Box{Vec3(L - dx, -1, -1), Vec3(2, 1, 1)};  // the last layer at x = L is held
  World w(s);
  // A half-sine velocity pulse of length 0.2 m centred at x = 0.3: it splits into two halves of amplitude
  // v0 / 2 running left and right.
  const double v0 = 0.02, xc = 0.3, half = 0.1;
  w.set_initial_velocity(0, [&](const Vec3& x0) {
    const double d = x0.x() - xc;
    return Vec3(std::abs(d) < half ? v0 * std::cos(0.5 * std::numbers::pi * d / half) : 0.0, 0, 0);
  });
  const std::vector<double> gauges = {0.555, 0.855, 1.055};
  std::vector<double> t_peak(gauges.size(), 0.0), v_peak(gauges.size(), 0.0), v_min(gauges.size(), 0.0);
  const double sample = 2e-5, t_end = 0.95 * (2 * L - xc - gauges[2]) / c_bar + 0.3 / c_bar;
  double t_prev = 0;
  std::vector<double> v_prev2(gauges.size(), 0), v_prev(gauges.size(), 0);
  while (w.time() < t_end) {
    w.advance_to(w.time() + sample, [] { return true; });
    for (std::size_t g = 0; g < gauges.size(); ++g) {
      const double v = mean_in_slab(w, gauges[g], dx, [&](std::size_t i) { return w.particles().v[i].x(); });
      // Peak: a local maximum of the sampled signal, refined by a parabola through three samples.
      if (v_prev[g] > v_peak[g] && v_prev[g] >= v && v_prev[g] >= v_prev2[g]) {
        const double a = v_prev2[g], b = v_prev[g], c = v;
        const double denom = a - 2 * b + c;
        const double shift = denom != 0.0 ? 0.5 * (a - c) / denom : 0.0;
        t_peak[g] = t_prev + shift * sample;
        v_peak[g] = b;
      }
      v_min[g] = std::min(v_min[g], v);
      v_prev2[g] = v_prev[g];
      v_prev[g] = v;
    }
    t_prev = w.time();
  }
  const double c = (gauges[1] - gauges[0]) / (t_peak[1] - t_peak[0]);
  INFO("measured pulse speed " << c << " m/s, bar speed " << c_bar << " m/s; peaks " << v_peak[0] << ", "
                               << v_peak[1] << " at " << t_peak[0] << ", " << t_peak[1] << " s");
  CHECK(std::abs(c / c_bar - 1.0) < 0.05);
  // Each half carries v0 / 2; dispersion and viscosity may lower the peak a little, not raise it.
  CHECK(v_peak[0] == Approx(0.5 * v0).epsilon(0.15));
  // Reflection at the fixed end: the velocity at x = 1.05 turns negative, about as large as it came in.
  INFO("gauge at 1.05 m: incoming peak " << v_peak[2] << ", reflected minimum " << v_min[2]);
  CHECK(v_min[2] < -0.6 * v_peak[2]);
}

TEST_CASE(
    "TL-SPH large deformation: a soft cantilever swings under gravity past 30 degrees, smooth and stable",
    "[solid][validation]") {
  // Issue 5, item 5. A 0.2 m cantilever (2 x 2 cm, 4 layers) released straight under gravity; E = 0.65 MPa
  // puts the linear static tip rotation at 2 rho g L^3 / (E H^2) = 0.6 rad, so the first swing passes well
  // beyond 30 degrees. Throughout: no particle moves off its reference neighbours (every pair that started dx
  // apart stays 0.75-1.3 dx apart: no collapse, no hourglass zig-zag) and the tip's cross-section moves as
  // one.
  const double L = 0.2, H = 0.02, dx = H / 4, E = 6.5e5;
  for (const char* model : {"saint_venant_kirchhoff", "neo_hookean"}) {
    Material mat = rubber(E, 0.3);
    mat.neo_hookean = std::string(model) == "neo_hookean";
    Scene sc = beam_scene(L, H, H, 0.03, dx, mat, Vec3(0, -9.81, 0));
    World w(sc);
    const Particles& P = w.particles();
    // Reference nearest-neighbour pairs, by particle id (the World may reorder its arrays).
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (std::size_t i = 0; i < P.size(); ++i)
      for (std::size_t j = i + 1; j < P.size(); ++j)
        if ((P.x0[j] - P.x0[i]).norm() < 1.01 * dx) pairs.emplace_back(P.id[i], P.id[j]);
    REQUIRE(pairs.size() > 0);
    const double x_tip = L - 0.5 * dx, x_back = L - 2.5 * dx;
    double max_rot = 0.0, t_max = 0.0, worst_lo = 1.0, worst_hi = 1.0, worst_spread = 0.0;
    // To 0.35 s: past the first swing's deepest point (0.27 s).
    while (w.time() < 0.35 - 1e-12) {
      w.advance_to(std::min(0.35, w.time() + 0.005), [] { return true; });
      std::map<uint32_t, std::size_t> at;
      for (std::size_t i = 0; i < P.size(); ++i) at[P.id[i]] = i;
      for (const auto& [a, b] : pairs) {
        const double r = (P.x[at[b]] - P.x[at[a]]).norm() / dx;
        worst_lo = std::min(worst_lo, r);
        worst_hi = std::max(worst_hi, r);
      }
      auto mean_pos = [&](double x) {
        return Vec3(mean_in_slab(w, x, dx, [&](std::size_t i) { return P.x[i].x(); }),
                    mean_in_slab(w, x, dx, [&](std::size_t i) { return P.x[i].y(); }),
                    mean_in_slab(w, x, dx, [&](std::size_t i) { return P.x[i].z(); }));
      };
      const Vec3 tip = mean_pos(x_tip), back = mean_pos(x_back);
      const double rot = std::atan2(back.y() - tip.y(), tip.x() - back.x());
      if (rot > max_rot) {
        max_rot = rot;
        t_max = w.time();
      }
      // The tip cross-section stays a section: its particles keep their reference distances from its centre.
      for (std::size_t i = 0; i < P.size(); ++i)
        if (std::abs(P.x0[i].x() - x_tip) < 0.5 * dx)
          worst_spread = std::max(
              worst_spread,
              std::abs((P.x[i] - tip).norm() - (P.x0[i] - Vec3(x_tip, 0.5 * H, 0.5 * H)).norm()) / dx);
    }
    const double deg = max_rot * 180.0 / std::numbers::pi;
    INFO(model << ": largest tip rotation " << deg << " deg at " << t_max << " s; neighbour distances "
               << worst_lo << "-" << worst_hi << " dx; tip section distortion " << worst_spread
               << " dx; steps " << w.steps());
    CHECK(deg > 30.0);
    CHECK(deg < 120.0);
    CHECK(worst_lo > 0.75);
    CHECK(worst_hi < 1.3);
    CHECK(worst_spread < 0.1);
  }
}

// Measurement harness for the cantilever period (issue 5, item 3), not yet a pass/fail test: at 4 layers the
// period is 1.20-1.31 x Euler-Bernoulli, at 6 layers 1.09-1.14 x (docs/validation.md). Environment: LAYERS,
// HG, AV, RATIO, CFL, PERIODS.
TEST_CASE("TL-SPH scratch: beam period vs resolution", "[.scratch]") {
  const double L = 0.2, H = 0.02;
  const int layers = std::getenv("LAYERS") ? std::atoi(std::getenv("LAYERS")) : 4;
  const double dx = H / layers;
  Material mat = rubber(2e6, 0.3975);
  if (std::getenv("HG")) mat.hourglass = std::atof(std::getenv("HG"));
  if (std::getenv("AV")) mat.solid_art_viscosity = std::atof(std::getenv("AV"));
  Scene sc = beam_scene(L, H, H, 0.03, dx, mat);
  if (std::getenv("RATIO")) sc.smoothing_ratio = std::atof(std::getenv("RATIO"));
  if (std::getenv("CFL")) sc.cfl = std::atof(std::getenv("CFL"));
  World w(sc);
  const double omega = std::pow(1.875104 / L, 2) * std::sqrt(2e6 * H * H / 12.0 / 1000.0);
  const double T = 2 * std::numbers::pi / omega;
  const double periods = std::getenv("PERIODS") ? std::atof(std::getenv("PERIODS")) : 2.2;
  const Oscillation o = vibrate(w, L, 0.05, periods * T, T / 200);
  WARN("layers " << layers << " period " << o.period / T << " x EB; decay " << o.decay << " crossings "
                 << o.crossings << " drift " << o.max_energy_drift << " steps " << w.steps());
}

TEST_CASE("TL-SPH in fluid: the fluid's background pressure does not squeeze a soft solid",
          "[solid][fluid]") {
  // A soft elastic slab on the floor of a closed box, still water above it, no gravity, a background
  // pressure of 2 kPa. Without gravity the water's pressure is the background alone, which is no load on
  // the body (a device of the fluid's discretisation): the slab must stay uncompressed. Had the reaction
  // kept the background, an unconfined slab would settle at a vertical strain of -pb / (lambda + 2 mu) = -15
  // %; in the closed box the water cannot follow, so the squeeze stops far earlier (see the numbers below).
  const double dx = 0.001;
  Scene s;
  s.name = "slab";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-0.01, -0.01, -0.01), Vec3(0.02, 0.02, 0.02)};
  s.max_dt = 1e-3;
  Material w = water(20.0);
  w.background_pressure = 2000.0;
  Material gel = rubber(1e4, 0.3);
  s.materials = {w, wall(), gel};
  Body slab = box_body("slab", 2, Vec3(0, 0, 0), Vec3(0.01, 0.004, 0.01));
  slab.fixed = Box{Vec3(-1, -1, -1), Vec3(1, 0.001, 1)};  // its bottom layer held (it does not sink)
  s.bodies = {slab, box_body("water", 0, Vec3(0, 0.004, 0), Vec3(0.01, 0.01, 0.01)),
              container("box", 1, Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), {})};
  World world(s);
  world.advance_to(0.004, [] { return true; });  // the slab's P-wave crosses it in 1 ms
  const Solids& S = world.solids();
  double fyy = 0.0;
  for (std::size_t k = 0; k < S.size(); ++k) fyy += S.F(k)(1, 1);
  fyy /= static_cast<double>(S.size());
  const SolidParams sp(gel);
  double uy_top = 0.0, f_top = 0.0;
  int n_top = 0;
  const Particles& P = world.particles();
  for (std::size_t k = 0; k < S.size(); ++k)
    if (P.x0[S.at(k)].y() > 0.003) {
      uy_top += P.x[S.at(k)].y() - P.x0[S.at(k)].y();
      f_top += S.F(k)(1, 1);
      ++n_top;
    }
  INFO("top layer: mean uy " << uy_top / n_top << " m, F_yy " << f_top / n_top);
  INFO("mean F_yy " << fyy << "; a background load would give " << 1.0 - 2000.0 / (sp.lambda + 2.0 * sp.mu));
  // With the background in the reaction the slab is pushed in (the confined water, bulk modulus rho c0^2,
  // soon stops it): measured 79 um down at the top at 4 ms, mean F_yy 0.974. Without it, nothing moves.
  CHECK(std::abs(uy_top / n_top) < 1e-6);
  CHECK(std::abs(fyy - 1.0) < 1e-3);
}
