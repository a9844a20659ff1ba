// One-layer shells (sim/solid/shell.hpp): patch tests (uniform stretch, rigid rotation, constant curvature,
// momentum), the clamped circular plate under pressure, a cantilever strip's frequency and energy, bad input,
// determinism.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>

#include "builders.hpp"
#include "cli_helpers.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "geometry/aortic_root.hpp"
#include "io/probes.hpp"
#include "scene_loader.hpp"
#include "solid/shell.hpp"
#include "world.hpp"

using namespace aortasph;
using namespace aortasph::test;

namespace {

Material shell_material(double E, double nu, double t, double rho = 1000.0) {
  return shell_sheet(E, nu, t, rho);
}

// An nx x ny lattice of shell particles in the xy-plane at spacing dx (normal +z), reference = current.
struct Sheet {
  Particles P;
  std::vector<ShellSeed> seed;
};
Sheet sheet(int nx, int ny, double dx) {
  Sheet s;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t n = s.P.size();
      s.P.resize(n + 1);
      s.P.x[n] = s.P.x0[n] = dx * Vec3(i + 0.5, j + 0.5, 0.0);
      s.P.kind[n] = Kind::Shell;
      s.P.id[n] = static_cast<uint32_t>(n);
      ShellSeed sd;
      sd.normal = Vec3::UnitZ();
      sd.area = dx * dx;
      s.seed.push_back(sd);
    }
  return s;
}

// A resultant of slot s (in its tangent frame T1, T2) in the global x, y axes of a sheet in the xy-plane.
Eigen::Matrix2d global_xy(const Shells& sh, std::size_t s, const Eigen::Matrix2d& M) {
  Eigen::Matrix2d R;
  R << sh.tangent(s, 0).x(), sh.tangent(s, 1).x(), sh.tangent(s, 0).y(), sh.tangent(s, 1).y();
  return R * M * R.transpose();
}

double D_of(double E, double nu, double t) {
  return E * t * t * t / (12.0 * (1.0 - nu * nu));
}

Scene plate_scene(double a, double t, double dx, double E, double nu, double rho, double p, double damping) {
  Scene s;
  s.name = "plate";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-2 * a, -2 * a, -2 * a), Vec3(2 * a, 2 * a, 2 * a)};
  s.max_dt = 1.0;
  s.cfl = 0.5;
  Material m = shell_material(E, nu, t, rho);
  m.shell_damping = damping;
  s.materials = {m};
  Body b;
  b.name = "plate";
  b.material = 0;
  b.shape.kind = ShapeKind::Disc;
  b.shape.center = Vec3::Zero();
  b.shape.radius = a;
  b.shape.normal = Vec3::UnitZ();
  b.shape.rim = 1;
  b.pressure_load = TimeSeries{{}, {p}};
  s.bodies = {b};
  return s;
}

// The energy's derivative is the stress: central differences of psi against S at a general strain E
// (stress(E) returns S and psi).
void check_energy_derivative(const std::function<std::pair<Mat3, double>(const Mat3&)>& stress,
                             const Mat3& E) {
  const Mat3 S = stress(E).first;
  for (const auto& [a, b] : {std::pair{0, 0}, {1, 1}, {0, 1}}) {
    Mat3 Ep = E, Em = E;
    const double h = 1e-7, k = a == b ? 1.0 : 0.5;  // an off-diagonal component appears twice
    Ep(a, b) += k * h, Ep(b, a) = Ep(a, b);
    Em(a, b) -= k * h, Em(b, a) = Em(a, b);
    CHECK((stress(Ep).second - stress(Em).second) / (2 * h) == Approx(S(a, b)).epsilon(1e-5));
  }
}

// Law a (with fibre direction fa, if any) and law b (none) give bitwise the same S, psi and stiffening at E.
void check_same_stress(const ShellParams& a, const ShellParams& b, const Mat3& E,
                       const Eigen::Vector2d* fa = nullptr) {
  Mat3 Sa, Sb;
  double pa = 0.0, pb = 0.0, sa = 1.0, sb = 1.0;
  shell_stress(a, E, Sa, pa, &sa, fa);
  shell_stress(b, E, Sb, pb, &sb);
  CHECK(Sa == Sb);
  CHECK(pa == pb);
  CHECK(sa == sb);
}

std::size_t nearest(const World& w, const Vec3& x) {
  const Particles& P = w.particles();
  std::size_t best = 0;
  for (std::size_t i = 0; i < P.size(); ++i)
    if ((P.x0[i] - x).squaredNorm() < (P.x0[best] - x).squaredNorm()) best = i;
  return best;
}

}  // namespace

TEST_CASE("shell patch test: a uniform in-plane stretch gives the analytic membrane force", "[shell]") {
  const double dx = 0.01, E = 1e6, nu = 0.3, t = 0.004;
  Sheet S = sheet(9, 7, dx);
  const std::vector<Material> mats = {shell_material(E, nu, t)};
  const CubicSpline kernel(1.3 * dx);
  const double e1 = 0.02, e2 = -0.01;
  for (std::size_t i = 0; i < S.P.size(); ++i)
    S.P.x[i] = Vec3((1 + e1) * S.P.x0[i].x(), (1 + e2) * S.P.x0[i].y(), 0);
  Shells sh(S.P, mats, kernel, S.seed);
  sh.update(S.P);
  const double E11 = e1 + 0.5 * e1 * e1, E22 = e2 + 0.5 * e2 * e2;
  const double c = E / (1 - nu * nu);
  const double N11 = t * c * (E11 + nu * E22), N22 = t * c * (E22 + nu * E11);
  for (std::size_t s = 0; s < sh.size(); ++s) {
    // Every particle, edges and corners included: the corrected gradient is exact for linear fields.
    const Eigen::Matrix2d N = global_xy(sh, s, sh.membrane(s));
    CHECK(N(0, 0) == Approx(N11).epsilon(1e-9));
    CHECK(N(1, 1) == Approx(N22).epsilon(1e-9));
    CHECK(std::abs(N(0, 1)) < 1e-9 * N11);
    CHECK(sh.moment(s).norm() < 1e-9 * N11 * t);
    CHECK(sh.shear(s).norm() < 1e-9 * N11);
    CHECK(sh.strain(s) == Approx(E11).epsilon(1e-9));  // the larger principal strain (the stress probe's)
  }
}

TEST_CASE("shell patch test: a rigid 90 degree rotation about any axis gives zero stress", "[shell]") {
  const double dx = 0.01, E = 1e6, nu = 0.3, t = 0.004;
  const std::vector<Material> mats = {shell_material(E, nu, t)};
  const CubicSpline kernel(1.3 * dx);
  for (const Vec3& axis : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 2, 3).normalized()}) {
    Sheet S = sheet(8, 8, dx);
    // Pre-stretched, so that objectivity is tested too: the rotated sheet has the same resultants.
    for (std::size_t i = 0; i < S.P.size(); ++i) S.P.x[i] = Vec3(1.01 * S.P.x0[i].x(), S.P.x0[i].y(), 0);
    Shells ref(S.P, mats, kernel, S.seed);
    ref.update(S.P);
    const Mat3 R = Eigen::AngleAxisd(std::numbers::pi / 2, axis).toRotationMatrix();
    for (std::size_t i = 0; i < S.P.size(); ++i) S.P.x[i] = R * S.P.x[i] + Vec3(0.3, -0.2, 0.1);
    Shells sh(S.P, mats, kernel, S.seed);
    for (std::size_t s = 0; s < sh.size(); ++s) sh.set_director(s, R * Vec3::UnitZ());
    sh.update(S.P);
    const double N0 = E * t * 0.01;
    for (std::size_t s = 0; s < sh.size(); ++s) {
      INFO("axis " << axis.transpose() << " particle " << s);
      CHECK((sh.membrane(s) - ref.membrane(s)).norm() < 1e-9 * N0);
      CHECK(sh.moment(s).norm() < 1e-9 * N0 * t);
      CHECK(sh.shear(s).norm() < 1e-9 * N0);
    }
    // And without the stretch, zero stress: a plain rigid rotation.
    Sheet U = sheet(8, 8, dx);
    for (std::size_t i = 0; i < U.P.size(); ++i) U.P.x[i] = R * U.P.x0[i];
    Shells rr(U.P, mats, kernel, U.seed);
    for (std::size_t s = 0; s < rr.size(); ++s) rr.set_director(s, R * Vec3::UnitZ());
    rr.update(U.P);
    std::vector<Vec3> f(U.P.size(), Vec3::Zero());
    rr.add_forces(f);
    for (std::size_t s = 0; s < rr.size(); ++s) {
      CHECK(rr.membrane(s).norm() < 1e-9 * N0);
      CHECK(rr.moment(s).norm() < 1e-9 * N0 * t);
      CHECK(f[rr.at(s)].norm() < 1e-9 * N0 * dx);
      CHECK(rr.torque(s).norm() < 1e-9 * N0 * dx * t);
      CHECK(rr.von_mises(s) < 1e-9 * E * 0.01);
    }
  }
}

TEST_CASE("shell viscosity: a rigid spin feels no Kelvin-Voigt force, a stretch rate the elastic law's shape",
          "[shell]") {
  const double dx = 0.01, E = 1e6, t = 0.004, eta = 50.0;
  std::vector<Material> mats = {shell_material(E, 0.0, t)};
  mats[0].shell_viscosity = eta;
  const CubicSpline kernel(1.3 * dx);
  // A sheet turned by R and spinning rigidly at Omega (positions, velocities and director spin): E' = 0.
  const Vec3 Omega = Vec3(3, -2, 5);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Sheet U = sheet(8, 8, dx);
  for (std::size_t i = 0; i < U.P.size(); ++i) U.P.x[i] = R * U.P.x0[i] + Vec3(0.3, -0.2, 0.1);
  Shells rr(U.P, mats, kernel, U.seed);
  std::vector<Vec3> v(rr.size());
  for (std::size_t s = 0; s < rr.size(); ++s) {
    rr.set_director(s, R * Vec3::UnitZ());
    rr.omegas()[s] = Omega;
    v[s] = Omega.cross(U.P.x[rr.at(s)]) + Vec3(1, 2, 3);
  }
  rr.update(U.P, &v);
  const double f0 = 2.0 * eta * Omega.norm() * t * dx;  // the force scale of a strain rate |Omega|
  double fmax = 0.0;
  for (std::size_t s = 0; s < rr.size(); ++s) {
    CHECK(rr.internal_force(s).norm() < 1e-9 * f0);
    CHECK(rr.torque(s).norm() < 1e-9 * f0 * t);
  }
  // The same sheet stretching along x at the rate r (v = (r x, 0, 0)): S_v = 2 eta r on the 11 component.
  // With nu = 0 the elastic law is S = E E, so every particle's viscous force is the force of the sheet
  // stretched by e (S11 = E (e + e^2 / 2), P11 = (1 + e) S11) scaled by 2 eta r / ((1 + e) E (e + e^2 / 2)).
  Sheet S = sheet(9, 7, dx);
  const double r = 20.0, e = 1e-3;
  Shells visc(S.P, mats, kernel, S.seed);
  std::vector<Vec3> vs(visc.size());
  for (std::size_t s = 0; s < visc.size(); ++s) vs[s] = Vec3(r * S.P.x0[visc.at(s)].x(), 0, 0);
  visc.update(S.P, &vs);
  Sheet T = sheet(9, 7, dx);
  for (std::size_t i = 0; i < T.P.size(); ++i) T.P.x[i] = Vec3((1 + e) * T.P.x0[i].x(), T.P.x0[i].y(), 0);
  Shells el(T.P, {shell_material(E, 0.0, t)}, kernel, T.seed);
  el.update(T.P);
  const double scale = 2.0 * eta * r / ((1 + e) * E * (e + 0.5 * e * e));
  for (std::size_t s = 0; s < visc.size(); ++s) {
    INFO("particle " << s);
    fmax = std::max(fmax, visc.internal_force(s).norm());
    CHECK((visc.internal_force(s) - scale * el.internal_force(s)).norm() <
          1e-6 * scale * el.internal_force(s).norm() + 1e-12);
  }
  CHECK(fmax > 0.1 * 2.0 * eta * r * t * dx);  // the edges carry it: not zero
  // Without the velocities (update(P)) the viscous sheet is the elastic one: no force at rest.
  visc.update(S.P);
  for (std::size_t s = 0; s < visc.size(); ++s)
    CHECK(visc.internal_force(s).norm() < 1e-9 * 2.0 * eta * r * t * dx);
}

TEST_CASE("shell patch test: a constant-curvature bend gives M = D kappa", "[shell]") {
  // A strip bent onto a cylinder of radius Rb about the y axis, length preserved, directors the cylinder's
  // normals: kappa = 1 / Rb, M11 = D kappa, M22 = nu D kappa, no membrane force.
  const double dx = 0.01, E = 1e6, nu = 0.3, t = 0.004, Rb = 0.5;
  Sheet S = sheet(21, 11, dx);
  const std::vector<Material> mats = {shell_material(E, nu, t)};
  const CubicSpline kernel(1.3 * dx);
  const double xc = 0.105;
  auto bend = [&](const Vec3& X) {
    const double th = (X.x() - xc) / Rb;
    return Vec3(xc + Rb * std::sin(th), X.y(), Rb * (1 - std::cos(th)));
  };
  auto dir = [&](const Vec3& X) {
    const double th = (X.x() - xc) / Rb;
    return Vec3(-std::sin(th), 0, std::cos(th));
  };
  for (std::size_t i = 0; i < S.P.size(); ++i) S.P.x[i] = bend(S.P.x0[i]);
  Shells sh(S.P, mats, kernel, S.seed);
  for (std::size_t s = 0; s < sh.size(); ++s) sh.set_director(s, dir(sh.reference(s)));
  sh.update(S.P);
  const double D = D_of(E, nu, t), Mk = D / Rb;
  int checked = 0;
  for (std::size_t s = 0; s < sh.size(); ++s) {
    const Vec3 X = sh.reference(s);
    // Interior particles (a full kernel support): the bend is not linear, so edges are first order only.
    if (X.x() < 3 * dx || X.x() > 0.21 - 3 * dx || X.y() < 3 * dx || X.y() > 0.11 - 3 * dx) continue;
    INFO("particle at " << X.transpose());
    const Eigen::Matrix2d M = global_xy(sh, s, sh.moment(s)), N = global_xy(sh, s, sh.membrane(s));
    CHECK(std::abs(M(0, 0)) == Approx(Mk).epsilon(0.002));
    CHECK(std::abs(M(1, 1)) == Approx(nu * Mk).epsilon(0.002));
    CHECK(std::abs(M(0, 1)) < 1e-6 * Mk);
    // The gradient of the curved mid-surface is exact to O((dx / Rb)^2) only (the sum over chords): a
    // membrane strain below (dx / Rb)^2 / 2 = 2e-4, against a bending strain of t / (2 Rb) = 4e-3 at the
    // faces.
    CHECK(N.cwiseAbs().maxCoeff() < 0.5 * (dx / Rb) * (dx / Rb) * E * t / (1 - nu * nu));
    CHECK(sh.shear(s).norm() < 1e-4 * E * t);
    ++checked;
  }
  CHECK(checked > 20);
  // The edges carry the same moment to within 5 % (first-order gradients there).
  for (std::size_t s = 0; s < sh.size(); ++s)
    CHECK(std::abs(global_xy(sh, s, sh.moment(s))(0, 0)) == Approx(Mk).epsilon(0.05));
}

TEST_CASE("shell: internal forces conserve linear and angular momentum", "[shell]") {
  const double dx = 0.01, E = 1e6, nu = 0.3, t = 0.004;
  Sheet S = sheet(9, 8, dx);
  const std::vector<Material> mats = {shell_material(E, nu, t)};
  const CubicSpline kernel(1.3 * dx);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Shells sh(S.P, mats, kernel, S.seed);
  for (std::size_t i = 0; i < S.P.size(); ++i) S.P.x[i] += 0.1 * dx * Vec3(u(rng), u(rng), u(rng));
  for (std::size_t s = 0; s < sh.size(); ++s) sh.set_director(s, Vec3(0.2 * u(rng), 0.2 * u(rng), 1.0));
  sh.update(S.P);
  std::vector<Vec3> f(S.P.size(), Vec3::Zero());
  sh.add_forces(f);
  Vec3 F = Vec3::Zero(), L = Vec3::Zero();
  double scale = 0.0, lscale = 0.0;
  for (std::size_t s = 0; s < sh.size(); ++s) {
    const Vec3& fi = f[sh.at(s)];
    F += fi;
    L += S.P.x[sh.at(s)].cross(fi) + sh.torque(s);
    scale += fi.norm();
    lscale += S.P.x[sh.at(s)].norm() * fi.norm() + sh.torque(s).norm();
  }
  REQUIRE(scale > 0.0);
  CHECK(F.norm() < 1e-12 * scale);
  CHECK(L.norm() < 1e-12 * lscale);
}

namespace {

// A closed cylinder of radius R (axis x, periodic along x over nx rows), nth particles round; positions
// x0 + u(x0), u given in (axial, hoop, radial) components of the reference point's frame.
struct Cylinder {
  Particles P;
  std::vector<ShellSeed> seed;
  Periodic per;
};
Cylinder cylinder(double R, int nth, int nx, const std::function<Vec3(double, double)>& u) {
  Cylinder c;
  const double dth = 2 * std::numbers::pi / nth, dl = R * dth;
  for (int j = 0; j < nth; ++j)
    for (int i = 0; i < nx; ++i) {
      const double th = (j + 0.5) * dth, x = (i + 0.5) * dl;
      const Vec3 er(0, std::sin(th), std::cos(th)), et(0, std::cos(th), -std::sin(th));
      const std::size_t n = c.P.size();
      c.P.resize(n + 1);
      c.P.x0[n] = Vec3(x, 0, 0) + R * er;
      const Vec3 d = u(x, th);
      c.P.x[n] = c.P.x0[n] + d.x() * Vec3::UnitX() + d.y() * et + d.z() * er;
      c.P.kind[n] = Kind::Shell;
      c.P.id[n] = static_cast<uint32_t>(n);
      ShellSeed sd;
      sd.normal = er;
      sd.area = dl * R * dth;
      c.seed.push_back(sd);
    }
  c.per = Periodic(Box{Vec3(0, -2 * R, -2 * R), Vec3(nx * dl, 2 * R, 2 * R)}, {true, false, false});
  return c;
}

}  // namespace

TEST_CASE("shell: a cylinder bent without stretching (ring ovalization) carries bending energy only",
          "[shell]") {
  // The inextensional n = 2 mode of a long cylinder, w = W cos 2 theta, v = -W/2 sin 2 theta (hoop strain
  // (v' + w) / R = 0): Kirchhoff-Love energy 1/2 D (3 W / R^2)^2 pi R L, no membrane energy. R / t = 100
  // and dx / t = 9.8 (64 round), as in the Scordelis-Lo roof at 17 on its arc. Without the membrane
  // strain's curvature correction (Shells::update) the discrete tangents' third-order error read as a hoop
  // strain: 4.3 times the exact energy here (membrane locking; docs/validation.md "Shells").
  const double R = 25, t = 0.25, E = 4.32e8, W = 1e-4 * t;
  const int nth = 64, nx = 10;
  const double pi = std::numbers::pi, L = nx * 2 * pi * R / nth;
  Cylinder c = cylinder(R, nth, nx, [&](double, double th) {
    return Vec3(0, -0.5 * W * std::sin(2 * th), W * std::cos(2 * th));
  });
  const std::vector<Material> mats = {shell_material(E, 0.0, t)};
  const CubicSpline kernel(1.3 * 2 * pi * R / nth);
  Shells sh(c.P, mats, kernel, c.seed, c.per);
  // Directors along the discrete mid-surface's normal: no transverse shear.
  sh.update(c.P);
  for (std::size_t s = 0; s < sh.size(); ++s) sh.set_director(s, sh.normal(s));
  sh.update(c.P);
  double um = 0.0, ub = 0.0;
  for (std::size_t s = 0; s < sh.size(); ++s) {
    um += sh.area(s) * sh.membrane(s).squaredNorm() / (2 * E * t);
    ub += sh.area(s) * sh.moment(s).squaredNorm() * 12 / (2 * E * t * t * t);
  }
  const double D = E * t * t * t / 12, exact = 0.5 * D * std::pow(3 * W / (R * R), 2) * pi * R * L;
  INFO("energy " << sh.energy() << ", exact " << exact << "; membrane " << um << ", bending " << ub);
  // Measured: 0.992 of the exact energy (the rest of it the hourglass control's), membrane 0.3 % of the
  // bending; without the correction 4.3 times the exact energy.
  CHECK(sh.energy() == Approx(exact).epsilon(0.02));
  CHECK(um < 0.01 * ub);
}

TEST_CASE("shell: internal forces and director moments are the energy's derivatives on a curved sheet",
          "[shell]") {
  // A deformed, sheared patch of a cylinder (R / t = 50): central differences of the energy against the
  // forces and moments, for both materials (the curvature correction adds terms in G and H); and the same
  // cylinder squashed into a flat oval with the directors along its normals, sharply bent at two ends, where
  // the correction is saturated (Shells::update).
  for (const auto& [neo, folded] : {std::pair{false, false}, {true, false}, {false, true}, {true, true}}) {
    INFO((neo ? "neo-Hookean" : "Saint Venant-Kirchhoff") << (folded ? ", folded" : ""));
    const double W = folded ? 0.6 : 0.0;
    const auto disp = [W](double x, double th) {
      return Vec3(0.02 * std::sin(3 * th) + 0.01 * x,
                  0.03 * std::cos(2 * th) * (1 + x) - 0.5 * W * std::sin(2 * th),
                  0.05 * std::cos(th + x) + W * std::cos(2 * th));
    };
    Cylinder c = cylinder(1.0, 48, 8, disp);
    const auto normal_at = [&](const Vec3& X) {  // of the deformed surface, by central differences
      const auto p = [&](double x, double th) {
        const Vec3 er(0, std::sin(th), std::cos(th)), et(0, std::cos(th), -std::sin(th));
        const Vec3 d = disp(x, th);
        return Vec3(Vec3(x, 0, 0) + er + d.x() * Vec3::UnitX() + d.y() * et + d.z() * er);
      };
      const double x = X.x(), th = std::atan2(X.y(), X.z()), e = 1e-5;
      return Vec3((p(x + e, th) - p(x - e, th)).cross(p(x, th + e) - p(x, th - e)).normalized());
    };
    Material m = shell_material(1e6, 0.3, 0.02);
    m.neo_hookean = neo;
    const std::vector<Material> mats = {m};
    const CubicSpline kernel(1.3 * 2 * std::numbers::pi / 48);
    Shells sh(c.P, mats, kernel, c.seed, c.per);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (std::size_t s = 0; s < sh.size(); ++s)
      sh.set_director(s, (folded ? normal_at(sh.reference(s)) : sh.reference_normal(s)) +
                             0.05 * Vec3(u(rng), u(rng), u(rng)));
    sh.update(c.P);
    double fmax = 0.0, tmax = 0.0;
    for (std::size_t s = 0; s < sh.size(); ++s) {
      fmax = std::max(fmax, sh.internal_force(s).cwiseAbs().maxCoeff());
      tmax = std::max(tmax, sh.torque(s).cwiseAbs().maxCoeff());
    }
    for (const std::size_t s : {std::size_t{5}, std::size_t{50}, std::size_t{90}}) {
      const std::size_t i = sh.at(s);
      const Vec3 f = sh.internal_force(s), tau = sh.torque(s), d = sh.director(s);
      for (int k = 0; k < 3; ++k) {
        const double e = 1e-7;
        const Vec3 x = c.P.x[i];
        c.P.x[i][k] = x[k] + e;
        sh.update(c.P);
        const double up = sh.energy();
        c.P.x[i][k] = x[k] - e;
        sh.update(c.P);
        const double um = sh.energy();
        c.P.x[i] = x;
        CHECK(std::abs(-(up - um) / (2 * e) - f[k]) < 1e-6 * fmax);
        const Vec3 ax = Vec3::Unit(k);
        sh.set_director(s, d + e * ax.cross(d));
        sh.update(c.P);
        const double rp = sh.energy();
        sh.set_director(s, d - e * ax.cross(d));
        sh.update(c.P);
        const double rm = sh.energy();
        sh.set_director(s, d);
        CHECK(std::abs(-(rp - rm) / (2 * e) - tau[k]) < 1e-6 * tmax);
      }
    }
  }
}

TEST_CASE("shell: clamped circular plate under uniform pressure, centre deflection p a^4 / (64 D)",
          "[shell][long]") {
  // a / t = 20, small deflection (w / t ~ 0.003), damped to static (mass-proportional damping 2 omega_1,
  // critical for the first mode: omega_1 = 10.22 sqrt(D / (rho t)) / a^2).
  const double a = 0.5, t = 0.025, E = 1e9, nu = 0.3, rho = 1000.0, p = 100.0;
  const double D = D_of(E, nu, t), w_ref = p * a * a * a * a / (64.0 * D);
  const double omega1 = 10.22 * std::sqrt(D / (rho * t)) / (a * a);
  for (const int rings : {10, 16}) {
    const double dx = a / rings;
    World w(plate_scene(a, t, dx, E, nu, rho, p, 2.0 * omega1));
    const std::size_t c = nearest(w, Vec3::Zero());
    w.advance_to(0.03, [] { return true; });
    const double w1 = w.particles().x[c].z() - w.particles().x0[c].z();
    w.advance_to(0.035, [] { return true; });
    const double w2 = w.particles().x[c].z() - w.particles().x0[c].z();
    WARN("clamped plate, " << rings << " rings (dx = " << dx / t << " t, " << w.particles().size()
                           << " particles, " << w.steps() << " steps): w = " << w2
                           << ", p a^4/(64 D) = " << w_ref << ", ratio " << w2 / w_ref
                           << ", change over the last 0.005 s " << (w2 - w1) / w_ref);
    CHECK(std::abs(w2 - w1) < 0.005 * w_ref);  // static
    CHECK(w2 == Approx(w_ref).epsilon(0.05));
  }
}

namespace {

// A cantilever strip along x: free length L, width b, clamped by three fixed rows at x < 0.
Scene strip_scene(double L, double b, double t, double dx, double E, double rho) {
  Scene s;
  s.name = "strip";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-2 * L, -2 * L, -2 * L), Vec3(2 * L, 2 * L, 2 * L)};
  s.max_dt = 1.0;
  s.cfl = 0.5;
  s.materials = {shell_material(E, 0.0, t, rho)};
  Body body;
  body.name = "strip";
  body.material = 0;
  body.shape.kind = ShapeKind::Rectangle;
  body.shape.center = Vec3(0.5 * (L - 3 * dx), 0, 0);
  body.shape.size = {L + 3 * dx, b};
  body.shape.normal = Vec3::UnitZ();
  body.shape.u_axis = Vec3::UnitX();
  body.shell_fixed = {Box{Vec3(-1, -1, -1), Vec3(0, 1, 1)}};
  s.bodies = {body};
  return s;
}

double total_energy(const World& w) {
  const Particles& P = w.particles();
  double kin = 0.0;
  // Shell particles: their own leapfrog velocity (P.v is its mean over the sub-cycled step, what the fluid
  // sees).
  const std::vector<Vec3>& vs = w.shell_velocities();
  for (std::size_t i = 0; i < P.size(); ++i) {
    const long s = w.shells().slot(i);
    const Vec3& v = s >= 0 && !vs.empty() ? vs[static_cast<std::size_t>(s)] : P.v[i];
    kin += 0.5 * w.inertial_mass(i) * v.squaredNorm();
  }
  return kin + w.shells().rotational_energy() + w.shells().energy();
}

}  // namespace

// A cantilever strip started in its first mode, undamped, run for `periods` first periods: its frequency
// against Euler-Bernoulli and the spread of its total energy.
static void cantilever_frequency_and_energy(double periods) {
  // L / t = 10, nu = 0 (plate strip = beam), 80 particles along, 3 across (Timoshenko's shear and rotary
  // inertia lower f1 by about 0.5 % at this slenderness). The error is first order in dx (the clamp: 8.6 %,
  // 5.4 %, 3.3 % low at 20, 40, 80 particles along; docs/validation.md). f1 = 1.875^2 / (2 pi L^2)
  // sqrt(E I / (rho A)), I / A = t^2 / 12. Started in the first mode shape with a small velocity, undamped.
  const double L = 1.0, t = L / 10, dx = L / 80, b = 3 * dx, E = 1e7, rho = 1000.0;
  World w(strip_scene(L, b, t, dx, E, rho));
  const double beta = 1.8751040687;
  const double f1 = beta * beta / (2 * std::numbers::pi * L * L) * std::sqrt(E * t * t / (12 * rho));
  const double sigma = (std::cosh(beta) + std::cos(beta)) / (std::sinh(beta) + std::sin(beta));
  auto mode = [&](double x) {
    const double z = beta * x / L;
    return std::cosh(z) - std::cos(z) - sigma * (std::sinh(z) - std::sin(z));
  };
  const double v0 = 1e-3 * L * 2 * std::numbers::pi * f1;  // tip amplitude 1e-3 L
  w.set_initial_velocity(0,
                         [&](const Vec3& x0) { return Vec3(0, 0, x0.x() > 0 ? v0 * mode(x0.x()) / 2 : 0); });
  const std::size_t tip = nearest(w, Vec3(L, 0, 0));
  std::vector<double> ups;  // zero crossings of the tip's displacement, half a period apart
  double prev = 0.0, prev_t = 0.0;
  const double T = 1.0 / f1;
  double e_min = 1e300, e_max = -1e300;
  for (int k = 1; k <= 40 * periods; ++k) {
    w.advance_to(k * T / 40, [&] {
      const double z = w.particles().x[tip].z();
      if ((prev < 0.0 && z >= 0.0) || (prev > 0.0 && z <= 0.0))
        ups.push_back(prev_t + (w.time() - prev_t) * (-prev) / (z - prev));
      prev = z;
      prev_t = w.time();
      return true;
    });
    const double e = total_energy(w);
    e_min = std::min(e_min, e);
    e_max = std::max(e_max, e);
  }
  REQUIRE(ups.size() >= 3);
  const double period = 2.0 * (ups.back() - ups.front()) / static_cast<double>(ups.size() - 1);
  WARN("cantilever strip: f = " << 1.0 / period << " Hz, Euler-Bernoulli " << f1 << " Hz, ratio "
                                << f1 * period << "; energy " << e_min << " .. " << e_max << " ("
                                << (e_max - e_min) / e_max * 100 << " %), " << w.steps() << " steps");
  CHECK(1.0 / period == Approx(f1).epsilon(0.05));
  CHECK((e_max - e_min) < 0.01 * e_max);
}

TEST_CASE("shell: a cantilever strip's first frequency is Euler-Bernoulli's, and its energy is conserved",
          "[shell][long]") {
  cantilever_frequency_and_energy(2.0);
}

// Issue 16 asks for the energy over 10 periods (scripts/validate_shell.sh; 5x the test's run).
TEST_CASE("shell validation: a cantilever strip's energy over ten periods", "[.shell-validation]") {
  cantilever_frequency_and_energy(10.0);
}

// [heavy]: 0.3 s in Release, 34 s under the sanitizers (whose shards skip [heavy]; the viscous code path is
// covered there by "a rigid spin feels no Kelvin-Voigt force").
// A clamped bar's first axial mode with and without the Kelvin-Voigt viscosity (`dynamic_viscosity`): with
// nu = 0 the in-plane viscous stress 2 eta E' is the elastic E E times 2 eta / E, a stiffness-proportional
// (Rayleigh) damping, so each in-plane mode decays at zeta = eta omega / E with its own omega.
static std::pair<double, double> bar_axial_mode(double eta, double periods) {
  const double L = 0.2, dx = L / 20, E = 1e7, rho = 1000.0;
  Scene sc = strip_scene(L, 3 * dx, dx, dx, E, rho);
  sc.materials[0].shell_viscosity = eta;
  sc.domain = {Vec3(-0.25 * L, -0.25 * L, -0.25 * L), Vec3(1.25 * L, 0.25 * L, 0.25 * L)};  // a small grid
  World w(sc);
  const double c = std::sqrt(E / rho), T = 4 * L / c, v0 = 1e-4 * c;
  w.set_initial_velocity(0, [&](const Vec3& x0) {
    return Vec3(x0.x() > 0 ? v0 * std::sin(std::numbers::pi * x0.x() / (2 * L)) : 0, 0, 0);
  });
  const std::size_t tip = nearest(w, Vec3(L, 0, 0));
  std::vector<double> u;
  const int per = 200;
  for (int k = 1; k <= per * periods; ++k) {
    w.advance_to(k * T / per, [] { return true; });
    u.push_back(w.particles().x[tip].x() - w.particles().x0[tip].x());
  }
  // Extrema of u (parabola through the three samples about each) and the zero crossings.
  std::vector<double> amp, tz;
  for (std::size_t k = 1; k + 1 < u.size(); ++k) {
    if ((u[k] > u[k - 1] && u[k] >= u[k + 1]) || (u[k] < u[k - 1] && u[k] <= u[k + 1])) {
      const double a = 0.5 * (u[k - 1] + u[k + 1]) - u[k], b = 0.5 * (u[k + 1] - u[k - 1]);
      amp.push_back(std::abs(u[k] - b * b / (4 * a)));
    }
    if ((u[k - 1] < 0) != (u[k] < 0)) tz.push_back((k - 1 + u[k - 1] / (u[k - 1] - u[k])) * T / per);
  }
  REQUIRE(amp.size() >= 4);
  REQUIRE(tz.size() >= 3);
  const double omega = std::numbers::pi * static_cast<double>(tz.size() - 1) / (tz.back() - tz.front());
  const double delta = std::log(amp.front() / amp.back()) / static_cast<double>(amp.size() - 1);  // per half
  const double zeta = delta / std::sqrt(std::numbers::pi * std::numbers::pi + delta * delta);
  return {omega, zeta};
}

TEST_CASE("shell viscosity: a bar's axial mode decays at zeta = eta omega / E", "[shell][heavy]") {
  const double E = 1e7, L = 0.2, omega0 = std::numbers::pi / 2 * std::sqrt(E / 1000.0) / L;
  const auto [w_el, z_el] = bar_axial_mode(0.0, 3.0);
  const double eta = 0.05 * E / omega0;
  const auto [w_v, z_v] = bar_axial_mode(eta, 3.0);
  WARN("bar axial mode: omega " << w_el << " rad/s (continuum " << omega0 << "), zeta " << z_el
                                << "; with eta = " << eta << " Pa s: omega " << w_v << ", zeta " << z_v
                                << " against eta omega / E = " << eta * w_el / E);
  CHECK(w_el == Approx(omega0).epsilon(0.1));  // 5 % low: the clamp's first-order error, as the cantilever's
  CHECK(std::abs(z_el) < 0.002);
  CHECK(z_v == Approx(eta * w_el / E).epsilon(0.05));
}

TEST_CASE("shell viscosity: a strongly viscous plate shaken at every wavelength only loses energy",
          "[shell][heavy]") {
  // A free square plate (no support) with random velocities on every particle: all its modes, the edge's
  // fastest included, at a viscosity that sets the sub-step (Shells::stable_dt): the total energy must fall
  // at every sample and end far below its start (an anti-dissipative or unstable viscous term fails).
  const double a = 0.1, dx = a / 12, E = 1e6, rho = 1000.0;
  Scene sc = strip_scene(a, a, 0.5 * dx, dx, E, rho);
  sc.bodies[0].shell_fixed.clear();
  sc.domain = {Vec3(-a, -a, -a), Vec3(a, a, a)};
  sc.materials[0].shell_viscosity = 500.0;
  World w(sc);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> v0(w.particles().size());
  for (Vec3& v : v0) v = Vec3(u(rng), u(rng), u(rng));
  std::size_t k = 0;
  w.set_initial_velocity(0, [&](const Vec3&) { return v0[k++ % v0.size()]; });
  const double e0 = total_energy(w);
  double prev = e0;
  bool falls = true;
  for (int i = 1; i <= 100; ++i) {
    w.advance_to(i * 1e-4, [] { return true; });
    const double e = total_energy(w);
    if (!(e <= prev * (1 + 1e-9))) falls = false;
    prev = e;
  }
  WARN("viscous plate: energy " << e0 << " -> " << prev << " J in " << w.steps() << " steps");
  CHECK(falls);
  // The in-plane share of the random energy (about two thirds) is damped within the run; the transverse
  // shear, the rigid motions and the slowest bending modes are not, so the energy does not go to 0 (Release:
  // 20 % of e0 at the end, a sanitizer build 21 %). Undamped, it would stay at e0.
  CHECK(prev < 0.5 * e0);
}

TEST_CASE("shell: a strip periodic across its width bends cylindrically, as the plane-strain plate",
          "[shell][periodic][heavy]") {
  // The plate of O'Connor & Rogers 2021 (scenes/shell_hydrostatic_fsi.json) without its water: L = 1 m
  // between the clamped end rows (x = 0 and L), t = 0.05 m, aluminium, a uniform 20.9 kPa load (the 2 m
  // column plus the plate's weight), periodic in z across a slab 16 spacings wide. Cylindrical bending:
  // w(L/2) = q L^4 / (384 D) with the plate's D = E t^3 / (12 (1 - nu^2)), 7.059e-5 m (a strip with free long
  // edges would bend as a beam, E t^3 / 12, 10 % more). Measured: 0.936 of it at L/20, 0.977 at L/40, 1.003
  // at L/80 (first order: the clamp).
  const double L = 1.0, t = 0.05, E = 6.75e10, nu = 0.3, rho = 2700.0, dx = L / 40, width = 16 * dx;
  const double q = 1000.0 * 9.81 * 2.0 + rho * t * 9.81,
               w_ref = q * std::pow(L, 4) / (384.0 * D_of(E, nu, t));
  Scene s;
  s.name = "periodic_strip";
  s.spacing = dx;
  s.gravity = Vec3(0, -9.81, 0);
  s.domain = {Vec3(-0.2, -0.2, 0), Vec3(L + 0.2, 0.2, width)};
  s.periodic = {false, false, true};
  s.max_dt = 1e-3;
  s.cfl = 0.25;
  s.materials = {shell_sheet(E, nu, t, rho, 3000.0)};
  Body b;
  b.name = "plate";
  b.material = 0;
  b.shape.kind = ShapeKind::Rectangle;
  b.shape.center = Vec3(0.5 * L, 0, 0.5 * width);
  b.shape.size = {L + dx, width};  // rows at x = 0, dx, ..., L
  b.shape.normal = Vec3::UnitY();
  b.shape.u_axis = Vec3::UnitX();
  b.shell_fixed = {Box{Vec3(-1, -1, -1), Vec3(0.1 * dx, 1, 1)},
                   Box{Vec3(L - 0.1 * dx, -1, -1), Vec3(2, 1, 1)}};
  b.pressure_load = TimeSeries{{}, {-1000.0 * 9.81 * 2.0}};
  s.bodies = {b};
  World w(s);
  w.advance_to(0.012, [] { return true; });  // static by 0.01 s (damping 3000 /s)
  const Particles& P = w.particles();
  double lo = 1e30, hi = -1e30;  // the mid-span row, all across the width (the seam included)
  std::size_t n = 0;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (std::abs(P.x0[i].x() - 0.5 * L) < 0.25 * dx) {
      const double uy = P.x[i].y() - P.x0[i].y();
      lo = std::min(lo, uy), hi = std::max(hi, uy), ++n;
    }
  INFO("mid-span deflection " << -lo << " .. " << -hi << " m over " << n
                              << " particles, q L^4 / (384 D) = " << w_ref << " m, ratio " << -lo / w_ref);
  CHECK(n == 16);
  CHECK(-lo == Approx(w_ref).epsilon(0.05));
  CHECK(hi - lo < 1e-6 * w_ref);  // uniform across the width: no edge, the sheet closes on itself
}

TEST_CASE("shell: 1 and 2 threads give bitwise the same run", "[shell][heavy]") {
  const int before = max_threads();
  uint64_t hash[2] = {0, 0};
  Vec3 d[2];
  for (int k = 0; k < 2; ++k) {
    set_threads(k + 1);
    World w(plate_scene(0.5, 0.025, 0.05, 1e9, 0.3, 1000.0, 1e4, 0.0));
    w.advance_to(1e-3, [] { return true; });
    hash[k] = state_hash(w);
    d[k] = w.shells().director(w.shells().size() / 3);
  }
  set_threads(before);
  CHECK(hash[0] == hash[1]);
  CHECK(d[0] == d[1]);
}

namespace {

// A small valid shell scene (a cantilever strip clamped at x < 0, pressure on it); each row below breaks one
// thing.
const char* kShellGood = R"({
  "name": "strip",
  "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
  "resolution": { "spacing": 0.02 },
  "time": { "end": 0.0002, "output_interval": 0.0001 },
  "gravity": [0, 0, 0],
  "materials": { "sheet": { "type": "shell", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01 },
                 "rubber": { "type": "elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3 } },
  "bodies": [
    { "name": "strip", "material": "sheet",
      "shape": { "rectangle": { "center": [0.2, 0, 0], "size": [0.4, 0.1], "normal": [0, 0, 1], "u_axis": [1, 0, 0] } },
      "fixed": { "min": [-1, -1, -1], "max": [0.03, 1, 1] }, "pressure_load": [[0, 0], [1, 10]] },
    { "name": "block", "material": "rubber", "shape": { "box": { "min": [0.5, 0.5, 0.5], "max": [0.6, 0.6, 0.6] } } }
  ],
  "probes": [ { "name": "tip", "type": "displacement", "body": "strip", "point": [0.4, 0, 0] } ]
})";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at == std::string::npos) throw std::runtime_error("test table: '" + from + "' not in the scene");
  return s.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("shell: bad input exits 2 naming the key", "[shell][bad-input]") {
  const auto dir = scratch("shell_bad");
  const std::string good = kShellGood;
  struct Row {
    std::string what, scene, expect;
  };
  const std::vector<Row> rows = {
      {"thickness 0", replaced(good, "\"thickness\": 0.01", "\"thickness\": 0"),
       "materials.sheet.thickness: must be positive"},
      {"thickness negative", replaced(good, "\"thickness\": 0.01", "\"thickness\": -0.01"),
       "materials.sheet.thickness: must be positive"},
      {"thickness of 5 spacings", replaced(good, "\"thickness\": 0.01", "\"thickness\": 0.1"),
       "materials.sheet.thickness: is 5.0 spacings: a shell may be at most 4.0 spacings thick"},
      {"thickness missing", replaced(good, ", \"thickness\": 0.01", ""),
       "materials.sheet.thickness: missing"},
      {"unknown shell model",
       replaced(good, "\"thickness\": 0.01", "\"thickness\": 0.01, \"model\": \"ogden\""),
       "materials.sheet.model: unknown value 'ogden'"},
      {"negative damping", replaced(good, "\"thickness\": 0.01", "\"thickness\": 0.01, \"damping\": -1"),
       "materials.sheet.damping: must not be negative"},
      {"negative dynamic_viscosity",
       replaced(good, "\"thickness\": 0.01", "\"thickness\": 0.01, \"dynamic_viscosity\": -3"),
       "materials.sheet.dynamic_viscosity: must not be negative"},
      {"rectangle samples nothing", replaced(good, "\"size\": [0.4, 0.1]", "\"size\": [0.4, 0.005]"),
       "bodies[0].shape.rectangle.size[1]: samples no particle"},
      {"disc samples nothing",
       replaced(good,
                "\"rectangle\": { \"center\": [0.2, 0, 0], \"size\": [0.4, 0.1], \"normal\": [0, 0, 1], "
                "\"u_axis\": [1, 0, 0] }",
                "\"disc\": { \"center\": [0.2, 0, 0], \"radius\": 0.005, \"normal\": [0, 0, 1] }"),
       "bodies[0].shape.disc.radius: samples no ring"},
      {"panel arc samples nothing",
       replaced(good,
                "\"rectangle\": { \"center\": [0.2, 0, 0], \"size\": [0.4, 0.1], \"normal\": [0, 0, 1], "
                "\"u_axis\": [1, 0, 0] }",
                "\"cylindrical_panel\": { \"center\": [0, 0, 0], \"axis\": [1, 0, 0], \"radius\": 0.1, "
                "\"length\": 0.4, \"angle\": 1, \"normal\": [0, 0, 1] }"),
       "bodies[0].shape.cylindrical_panel.angle: the arc samples no particle"},
      {"panel normal along the axis",
       replaced(good,
                "\"rectangle\": { \"center\": [0.2, 0, 0], \"size\": [0.4, 0.1], \"normal\": [0, 0, 1], "
                "\"u_axis\": [1, 0, 0] }",
                "\"cylindrical_panel\": { \"center\": [0, 0, 0], \"axis\": [1, 0, 0], \"radius\": 0.1, "
                "\"length\": 0.4, \"angle\": 60, \"normal\": [1, 0, 0] }"),
       "bodies[0].shape.cylindrical_panel.normal: must be perpendicular to axis"},
      {"u_axis along the normal", replaced(good, "\"u_axis\": [1, 0, 0]", "\"u_axis\": [0, 0, 2]"),
       "bodies[0].shape.rectangle.u_axis: is parallel to normal"},
      {"pressure_load on an elastic body",
       replaced(good, "\"max\": [0.6, 0.6, 0.6] } } }",
                "\"max\": [0.6, 0.6, 0.6] } }, \"pressure_load\": 5 }"),
       "bodies[1].pressure_load: only shell bodies carry a pressure_load"},
      {"pinned on an elastic body",
       replaced(good, "\"max\": [0.6, 0.6, 0.6] } } }",
                "\"max\": [0.6, 0.6, 0.6] } }, \"pinned\": { \"min\": [0, 0, 0], \"max\": [1, 1, 1] } }"),
       "bodies[1].pinned: only shell bodies can be pinned"},
      {"pressure table not increasing", replaced(good, "[[0, 0], [1, 10]]", "[[0, 0], [0, 10]]"),
       "bodies[0].pressure_load[1]: times must increase strictly"},
      {"fixed region holds no particle",
       replaced(good, "\"fixed\": { \"min\": [-1, -1, -1], \"max\": [0.03, 1, 1] }",
                "\"fixed\": { \"min\": [-1, -1, -1], \"max\": [-0.5, 1, 1] }"),
       "bodies[0] 'strip'.fixed: the region holds no particle of the body"},
      {"second pinned box holds no particle",
       replaced(good, "\"fixed\": { \"min\": [-1, -1, -1], \"max\": [0.03, 1, 1] }",
                "\"pinned\": [ { \"min\": [-1, -1, -1], \"max\": [0.03, 1, 1] }, { \"min\": [0.9, -1, -1], "
                "\"max\": [1, 1, 1] } ]"),
       "bodies[0] 'strip'.pinned[1]: the region holds no particle of the body"},
      {"empty pinned list",
       replaced(good, "\"fixed\": { \"min\": [-1, -1, -1], \"max\": [0.03, 1, 1] }", "\"pinned\": []"),
       "bodies[0].pinned: expected a box or a non-empty list of boxes"},
      {"shell shape with an elastic material",
       replaced(good, "\"material\": \"sheet\"", "\"material\": \"rubber\""),
       "bodies[0].material: a shell shape (rectangle, disc, cylindrical_panel) needs a shell material"},
      {"lee_sacks without c1",
       replaced(good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
                "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"lee_sacks\", \"c2\": 20"),
       "materials.sheet.c1: missing"},
      {"lee_sacks with c2 0",
       replaced(
           good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
           "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"lee_sacks\", \"c1\": 1e4, \"c2\": 0"),
       "materials.sheet.c2: must be positive"},
      {"c1 on a neo_hookean shell",
       replaced(good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
                "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"neo_hookean\", \"c1\": 1e4"),
       "materials.sheet.c1: only the lee_sacks model takes c1, c2, c3 and delta (model is neo_hookean)"},
      {"lee_sacks delta above 1",
       replaced(good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
                "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"lee_sacks\", \"c1\": 1e5, "
                "\"c2\": 20, \"c3\": 5, \"delta\": 1.5"),
       "materials.sheet.delta: must lie in [0, 1], got 1.5"},
      {"lee_sacks fibres without c3",
       replaced(good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
                "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"lee_sacks\", \"c1\": 1e5, "
                "\"delta\": 0"),
       "materials.sheet.c3: missing"},
      {"fibres without a direction",
       replaced(good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
                "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"lee_sacks\", \"c1\": 1e5, "
                "\"c3\": 5, \"delta\": 0"),
       "bodies[0] 'strip'.fibre_direction: missing"},
      {"fibres along the normal",
       replaced(replaced(good, "\"poisson_ratio\": 0.3, \"thickness\": 0.01",
                         "\"poisson_ratio\": 0.5, \"thickness\": 0.01, \"model\": \"lee_sacks\", "
                         "\"c1\": 1e5, \"c3\": 5, \"delta\": 0"),
                "\"pressure_load\"", "\"fibre_direction\": [0, 0, 2], \"pressure_load\""),
       "bodies[0] 'strip'.fibre_direction: along the sheet's normal at particle 0"},
      {"a fibre direction for an isotropic sheet",
       replaced(good, "\"pressure_load\"", "\"fibre_direction\": [1, 0, 0], \"pressure_load\""),
       "bodies[0] 'strip'.fibre_direction: the body's material has no fibre term (lee_sacks with delta < 1)"},
      {"a fibre direction for an elastic body",
       replaced(good, "\"material\": \"rubber\", \"shape\"",
                "\"material\": \"rubber\", \"fibre_direction\": [1, 0, 0], \"shape\""),
       "bodies[1].fibre_direction: only shell bodies have a fibre direction"},
      {"lee_sacks compressible",
       replaced(good, "\"thickness\": 0.01",
                "\"thickness\": 0.01, \"model\": \"lee_sacks\", \"c1\": 1e4, \"c2\": 20"),
       "materials.sheet.poisson_ratio: the lee_sacks shell is incompressible"},
      {"displacement probe of an unknown body",
       replaced(good, "\"body\": \"strip\", \"point\"", "\"body\": \"stripe\", \"point\""),
       "probes[0].body: unknown body 'stripe'"},
  };
  for (const Row& r : rows) {
    std::ofstream(dir / "scene.json") << r.scene;
    std::string err;
    const int code = run_cli("check " + (dir / "scene.json").string(), err);
    INFO(r.what << ": exit " << code << ", stderr: " << err);
    CHECK(code == 2);
    CHECK(err.find(r.expect) != std::string::npos);
  }
  // The good scene runs and writes the displacement columns (and, with --vtk, the directors).
  std::ofstream(dir / "scene.json") << good;
  std::string err;
  CHECK(run_cli("run " + (dir / "scene.json").string() +
                    " --no-render --vtk --quiet --checkpoint-every 0.0002 --out " + (dir / "out").string(),
                err) == 0);
  const std::string csv = slurp(dir / "out" / "probes.csv");
  CHECK(csv.find("tip.ux,tip.uy,tip.uz") != std::string::npos);
  // VTK output carries the shells' director and thickness.
  const std::string vtp = slurp(dir / "out" / "vtk" / "particles_00001.vtp");
  CHECK(vtp.find("Name=\"director\"") != std::string::npos);
  CHECK(vtp.find("Name=\"thickness\"") != std::string::npos);
  // shell_putbacks.csv: a scene with shells writes it, its header and no row here (no fluid). A resumed run
  // keeps the rows up to its checkpoint (the end, 0.2 ms) and drops those after it (as a run killed after
  // writing them and before its next checkpoint would leave them) and a torn last line.
  const std::string header = "time,id,x,y,z,body,depth,sheet\n";
  CHECK(slurp(dir / "out" / "shell_putbacks.csv") == header);
  const std::string before = "0.0001,7,0,0,0,0,1e-05,1\n", after = "0.0002001,8,0,0,0,0,1e-05,0\n";
  { std::ofstream(dir / "out" / "shell_putbacks.csv", std::ios::app) << before << after << "0.0001,9,0"; }
  CHECK(run_cli("resume " + (dir / "out").string() + " --end-time 0.0003 --quiet", err) == 0);
  CHECK(slurp(dir / "out" / "shell_putbacks.csv") == header + before);
}

TEST_CASE("shell lee_sacks: the stress of the closed forms, the energy's derivative and the stiffening bound",
          "[shell]") {
  // Incompressible plane stress, psi = mu/2 x + c1/2 (exp(c2 x^2) - 1), x = I1 - 3, mu = E / 3.
  Material m = shell_sheet(3e5, 0.5, 1e-3, 1100.0);
  m.neo_hookean = true;
  m.lee_sacks_c1 = 1e4;
  m.lee_sacks_c2 = 20.0;
  const ShellParams p(m);
  const double mu = 1e5, c1 = 1e4, c2 = 20.0;
  auto W1 = [&](double x) { return 0.5 * mu + c1 * c2 * x * std::exp(c2 * x * x); };
  auto stress = [&](const Mat3& E, double* stiff = nullptr) {
    Mat3 S;
    double psi = 0.0;
    shell_stress(p, E, S, psi, stiff);
    return std::pair{S, psi};
  };
  auto green = [](double l1, double l2) {
    Mat3 E = Mat3::Zero();
    E(0, 0) = 0.5 * (l1 * l1 - 1.0);
    E(1, 1) = 0.5 * (l2 * l2 - 1.0);
    return E;
  };
  double prev_eq = 1.0, prev_uni = 1.0, tangent0_eq = 0.0, tangent0_uni = 0.0;
  const double dl = 1e-6;
  for (double l = 1.0; l <= 1.25 + 1e-12; l += 0.025) {
    // Equibiaxial stretch l: lambda3 = 1 / l^2, Cauchy sigma = 2 W1 (l^2 - l^-4), x = 2 l^2 + l^-4 - 3.
    const double xe = 2 * l * l + std::pow(l, -4) - 3.0;
    double se = 1.0;
    const auto [Se, psie] = stress(green(l, l), &se);
    CHECK(l * l * Se(0, 0) == Approx(2 * W1(xe) * (l * l - std::pow(l, -4))).margin(1e-6));
    CHECK(Se(1, 1) == Approx(Se(0, 0)).epsilon(1e-12));
    CHECK(psie == Approx(0.5 * mu * xe + 0.5 * c1 * (std::exp(c2 * xe * xe) - 1.0)).margin(1e-9));
    // Uniaxial stretch l: lambda2 = lambda3 = l^-1/2, S22 = 0, sigma = 2 W1 (l^2 - 1 / l), x = l^2 + 2 / l
    // - 3.
    const double xu = l * l + 2.0 / l - 3.0;
    double su = 1.0;
    const auto [Su, psiu] = stress(green(l, 1.0 / std::sqrt(l)), &su);
    CHECK(l * l * Su(0, 0) == Approx(2 * W1(xu) * (l * l - 1.0 / l)).margin(1e-6));
    CHECK(std::abs(Su(1, 1)) < 1e-6);
    // The stiffening bound: 1 unstrained, rising with the stretch and at least the rise of the tangent
    // d sigma / d lambda over its value at l = 1 (6 mu equibiaxial, 3 mu uniaxial), which sets the wave
    // speed.
    auto sig_eq = [&](double s) {
      const double x = 2 * s * s + std::pow(s, -4) - 3.0;
      return 2 * W1(x) * (s * s - std::pow(s, -4));
    };
    auto sig_uni = [&](double s) {
      const double x = s * s + 2.0 / s - 3.0;
      return 2 * W1(x) * (s * s - 1.0 / s);
    };
    const double te = (sig_eq(l + dl) - sig_eq(l > 1.0 ? l - dl : l)) / (l > 1.0 ? 2 * dl : dl);
    const double tu = (sig_uni(l + dl) - sig_uni(l > 1.0 ? l - dl : l)) / (l > 1.0 ? 2 * dl : dl);
    if (l == 1.0) {
      tangent0_eq = te, tangent0_uni = tu;
      CHECK(te == Approx(6 * mu).epsilon(1e-4));
      CHECK(tu == Approx(3 * mu).epsilon(1e-4));
      CHECK(se == 1.0);
      CHECK(su == 1.0);
    } else {
      CHECK(se > prev_eq);
      CHECK(su > prev_uni);
    }
    INFO("stretch " << l << ": stiffening " << se << " / " << su << ", tangent rise " << te / tangent0_eq
                    << " / " << tu / tangent0_uni);
    CHECK(se >= te / tangent0_eq);
    CHECK(su >= tu / tangent0_uni);
    // and not far above it (a step many times too short would cost the run for nothing)
    CHECK(se <= 4.0 * te / tangent0_eq);
    CHECK(su <= 4.0 * tu / tangent0_uni);
    prev_eq = se, prev_uni = su;
  }
  // The energy's derivative is the stress, for a general strain (shear included).
  Mat3 E = green(1.12, 0.97);
  E(0, 1) = E(1, 0) = 0.04;
  check_energy_derivative([&](const Mat3& e) { return stress(e); }, E);
  // c1 = 0 is the neo-Hookean law, bit for bit.
  Material nh = m;
  nh.lee_sacks_c1 = nh.lee_sacks_c2 = 0.0;
  Material z = m;
  z.lee_sacks_c1 = 0.0;
  check_same_stress(ShellParams(z), ShellParams(nh), E);
}

TEST_CASE(
    "shell lee_sacks with fibres: the fibre term's closed forms, tension only, the energy's derivative and "
    "the stiffening bound",
    "[shell]") {
  // psi = mu/2 x + c1/2 (delta (exp(c2 x^2) - 1) + (1 - delta) (exp(c3 y^2) - 1)), y = I4 - 1 > 0, mu = E /
  // 3; the leaflet's fit (docs/model.md): E = 1 MPa, c1 = 100 kPa, c3 = 5, delta = 0, and a mixed delta =
  // 0.5.
  for (const double delta : {0.0, 0.5}) {
    Material m = shell_sheet(1e6, 0.5, 1e-3, 1100.0);
    m.neo_hookean = true;
    m.lee_sacks_c1 = 1e5;
    m.lee_sacks_c2 = 20.0;
    m.lee_sacks_c3 = 5.0;
    m.lee_sacks_delta = delta;
    const ShellParams p(m);
    const double mu = 1e6 / 3.0, c1 = 1e5, c2 = 20.0, c3 = 5.0;
    auto W1 = [&](double x) { return 0.5 * mu + c1 * delta * c2 * x * std::exp(c2 * x * x); };
    auto W4 = [&](double y) { return y > 0.0 ? c1 * (1.0 - delta) * c3 * y * std::exp(c3 * y * y) : 0.0; };
    auto stress = [&](const Mat3& E, const Eigen::Vector2d& a, double* stiff = nullptr) {
      Mat3 S;
      double psi = 0.0;
      shell_stress(p, E, S, psi, stiff, &a);
      return std::pair{S, psi};
    };
    auto green = [](double l1, double l2) {
      Mat3 E = Mat3::Zero();
      E(0, 0) = 0.5 * (l1 * l1 - 1.0);
      E(1, 1) = 0.5 * (l2 * l2 - 1.0);
      return E;
    };
    const Eigen::Vector2d along(1.0, 0.0), across(0.0, 1.0);
    // Uniaxial stretch l along the fibres (lambda2 = lambda3 = l^-1/2 keeps S22 = 0: the fibre term has no
    // 22 part): sigma = 2 W1 (l^2 - 1 / l) + 2 l^2 W4(l^2 - 1).
    auto sig_fibre = [&](double l) {
      const double x = l * l + 2.0 / l - 3.0;
      return 2 * W1(x) * (l * l - 1.0 / l) + 2 * l * l * W4(l * l - 1.0);
    };
    // The stiffening bound is over the neo-Hookean's unstrained tangent 3 mu (the wave speed the step starts
    // from): it covers the tangent d sigma / d l along the fibres, within 4x. The fibres are stiff in tension
    // from the start (4 c1 (1 - delta) c3 at l = 1+), so the bound is above 1 unstrained.
    double prev = 0.0;
    const double dl = 1e-6;
    for (double l = 1.0; l <= 1.2 + 1e-12; l += 0.025) {
      const double x = l * l + 2.0 / l - 3.0, y = l * l - 1.0;
      double st = 1.0;
      const auto [S, psi] = stress(green(l, 1.0 / std::sqrt(l)), along, &st);
      INFO("delta " << delta << ", stretch " << l);
      CHECK(l * l * S(0, 0) == Approx(sig_fibre(l)).margin(1e-6));
      CHECK(std::abs(S(1, 1)) < 1e-6);
      CHECK(psi == Approx(0.5 * mu * x + 0.5 * c1 * delta * (std::exp(c2 * x * x) - 1.0) +
                          0.5 * c1 * (1.0 - delta) * (std::exp(c3 * y * y) - 1.0))
                       .margin(1e-9));
      // The same stretch across the fibres shortens them: the isotropic law alone (tension only).
      Mat3 Si, So;
      double pi = 0.0, po = 0.0;
      shell_stress(p, green(l, 1.0 / std::sqrt(l)), Si, pi, nullptr, &across);
      shell_stress(p, green(l, 1.0 / std::sqrt(l)), So, po);  // no fibre direction
      CHECK(Si == So);
      CHECK(pi == po);
      const double t = (sig_fibre(l + dl) - sig_fibre(l > 1.0 ? l - dl : l)) / (l > 1.0 ? 2 * dl : dl);
      if (l == 1.0) CHECK(t == Approx(3 * mu + 4 * c1 * (1.0 - delta) * c3).epsilon(1e-4));
      INFO("stiffening " << st << ", tangent over 3 mu " << t / (3 * mu));
      CHECK(st >= t / (3 * mu));
      CHECK(st <= 4.0 * t / (3 * mu));
      CHECK(st > prev);
      prev = st;
    }
    // At the fit's 16 % the fibres carry the tangent of the cusps' circumferential 15 MPa (delta 0).
    if (delta == 0.0) {
      const double l = 1.16, t = (sig_fibre(l + dl) - sig_fibre(l - dl)) / (2 * dl);
      CHECK(sig_fibre(l) == Approx(1.0e6).epsilon(0.03));
      CHECK(t == Approx(15e6).epsilon(0.05));
    }
    // Fibres at 30 degrees, a general strain: the energy's derivative is the stress, and S is symmetric.
    const Eigen::Vector2d a30(std::cos(std::numbers::pi / 6), std::sin(std::numbers::pi / 6));
    Mat3 E = green(1.12, 0.97);
    E(0, 1) = E(1, 0) = 0.04;
    CHECK(stress(E, a30).first(0, 1) == stress(E, a30).first(1, 0));
    check_energy_derivative([&](const Mat3& e) { return stress(e, a30); }, E);
  }
  // delta = 1 (the default) ignores a fibre direction: the isotropic law bit for bit.
  Material m = shell_sheet(1e6, 0.5, 1e-3, 1100.0);
  m.neo_hookean = true;
  m.lee_sacks_c1 = 1e4;
  m.lee_sacks_c2 = 20.0;
  m.lee_sacks_c3 = 5.0;
  Mat3 E = Mat3::Zero();
  E(0, 0) = 0.1, E(1, 1) = -0.02, E(0, 1) = E(1, 0) = 0.03;
  const Eigen::Vector2d a(1.0, 0.0);
  check_same_stress(ShellParams(m), ShellParams(m), E, &a);
}

TEST_CASE(
    "shell fibres: a body's fibre_direction and the aortic leaflets' circumferential fibres reach every "
    "particle, projected on its tangent plane",
    "[shell]") {
  // A flat strip with a direction out of its plane: the fibre is the direction's in-plane part, normalised.
  Scene s = plate_scene(0.5, 0.025, 0.05, 1e6, 0.5, 1000.0, 0.0, 0.0);
  s.materials[0].neo_hookean = true;
  s.materials[0].lee_sacks_c1 = 1e5;
  s.materials[0].lee_sacks_c3 = 5.0;
  s.materials[0].lee_sacks_delta = 0.0;
  s.bodies[0].fibre_direction = Vec3(1.0, 1.0, 1.0).normalized();
  const World w(s);
  const Shells& sh = w.shells();
  REQUIRE(sh.size() > 100);
  for (std::size_t k = 0; k < sh.size(); ++k) {
    INFO("particle " << k << " fibre " << sh.fibre(k).transpose());
    CHECK(sh.fibre(k).isApprox(Vec3(1.0, 1.0, 0.0).normalized(), 1e-12));
  }
  // Without a direction, the shell leaflets' own: horizontal and perpendicular to the radius before the
  // projection, so after it unit, in the tangent plane and along theta's in-plane part.
  AorticRootParams rp;
  rp.shell_leaflets = true;
  rp.mirror_leaflets = true;
  const ShapeSample leaf = sample_aortic_root(rp, AorticPart::Leaflet, 1, 0.001);
  REQUIRE(leaf.fibres.size() == leaf.points.size());
  for (std::size_t k = 0; k < leaf.points.size(); ++k) {
    const Vec3 q = leaf.points[k] - rp.base, f = leaf.fibres[k];
    CHECK(f.norm() == Approx(1.0).epsilon(1e-12));
    CHECK(std::abs(f.y()) < 1e-12);
    CHECK(std::abs(f.x() * q.x() + f.z() * q.z()) < 1e-12);
  }
}

TEST_CASE("shell lee_sacks: a stiffened plate takes shorter steps and resumes bitwise",
          "[shell][checkpoint]") {
  // The plate of the checkpoint test below, of tissue (E = 0.3 MPa, incompressible), under 2 kPa: it
  // bulges, its membrane stretches and stiffens, and the stable step shrinks with the stiffening; a
  // checkpoint carries the stiffening, so the resumed run takes the same steps.
  Scene s = plate_scene(0.5, 0.025, 0.05, 3e5, 0.5, 1000.0, 2e3, 50.0);
  s.materials[0].neo_hookean = true;
  Scene ls = s;
  ls.materials[0].lee_sacks_c1 = 1e4;
  ls.materials[0].lee_sacks_c2 = 20.0;
  World nh(s), a(ls);
  const double dt0 = a.shell_stable_dt();
  CHECK(dt0 == nh.shell_stable_dt());  // unstrained: the neo-Hookean's step
  a.advance_to(0.05, [] { return true; });
  nh.advance_to(0.05, [] { return true; });
  double most = 1.0;
  for (double st : a.shells().stiffening()) most = std::max(most, st);
  INFO("largest stiffening " << most << ", stable step " << a.shell_stable_dt() << " (unstrained " << dt0
                             << ", neo-Hookean now " << nh.shell_stable_dt() << ")");
  CHECK(most > 1.5);
  // The wave and shear-rotary limits scale with 1 / sqrt(stiffening) (the speed and the other limits only
  // shorten it further).
  CHECK(a.shell_stable_dt() <= dt0 / std::sqrt(most) * (1.0 + 1e-9));
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());
  World b(ls);
  b.load_state(in);
  a.advance_to(0.06, [] { return true; });
  b.advance_to(0.06, [] { return true; });
  CHECK(state_hash(a) == state_hash(b));
  CHECK(a.steps() == b.steps());
}

TEST_CASE("shell: a checkpoint resumes bitwise (directors and spin included)", "[shell][checkpoint]") {
  const Scene s = plate_scene(0.5, 0.025, 0.05, 1e9, 0.3, 1000.0, 1e4, 50.0);
  World a(s);
  a.advance_to(1e-3, [] { return true; });
  StateWriter out;
  a.save_state(out);
  const StateReader in(out.bytes());
  World b(s);
  b.load_state(in);
  a.advance_to(2e-3, [] { return true; });
  b.advance_to(2e-3, [] { return true; });
  CHECK(state_hash(a) == state_hash(b));
  bool same = true;
  for (std::size_t k = 0; k < a.shells().size(); ++k)
    same = same && a.shells().director(k) == b.shells().director(k) &&
           a.shells().omega(k) == b.shells().omega(k);
  CHECK(same);
  CHECK(a.shells().director(0) != Vec3::UnitZ());  // it did move
}

// Validations (scripts/validate_shell.sh, results in docs/validation.md): too slow for the test suite.
// The roll-up: a cantilever strip (L = 12, E = 1.2e6, nu = 0; Sze et al. 2004's roll-up, thicker so that it
// runs faster: the closed circle does not depend on t) under an end moment 2 pi E I / L on the directors of
// its last row, ramped up over six first periods and held for two, damping 2 omega_1; the tip must come back
// to the root. `periodic`: the strip is periodic across its width b (the plate strip in cylindrical bending,
// plane strain: no twist and no lateral mode). Diagnostics (docs/validation.md): ROLL_T, ROLL_DX, ROLL_B
// change the thickness, spacing and width, ROLL_TOP the moment's final fraction of 2 pi E I / L, ROLL_CFL,
// ROLL_HG the step and hourglass, ROLL_PLANAR=1 holds the directors in the bending plane.
static void roll_up(double b_default, bool periodic) {
  const double L = 12, E = 1.2e6, rho = 1000.0;
  const double b = std::getenv("ROLL_B") ? std::atof(std::getenv("ROLL_B")) : b_default;
  const double t = std::getenv("ROLL_T") ? std::atof(std::getenv("ROLL_T")) : 0.5;
  const double dx = std::getenv("ROLL_DX") ? std::atof(std::getenv("ROLL_DX")) : 0.25;
  Scene s = strip_scene(L, b, t, dx, E, rho);
  const double EI = E * b * t * t * t / 12, M = 2 * std::numbers::pi * EI / L;
  const double f1 = 1.8751 * 1.8751 / (2 * std::numbers::pi * L * L) * std::sqrt(E * t * t / (12 * rho));
  s.materials[0].shell_damping = 2 * 2 * std::numbers::pi * f1;
  s.domain = {Vec3(-20, -20, -20), Vec3(20, 20, 20)};
  if (std::getenv("ROLL_CFL")) s.cfl = std::atof(std::getenv("ROLL_CFL"));
  if (std::getenv("ROLL_HG")) s.materials[0].hourglass = std::atof(std::getenv("ROLL_HG"));
  if (periodic) {  // the period must hold 2.5 search radii: b >= 2 at dx = 0.25
    s.periodic = {false, true, false};
    s.domain.min.y() = -0.5 * b;
    s.domain.max.y() = 0.5 * b;
  }
  World w(s);
  Shells& sh = w.shells_for_test();
  std::vector<std::size_t> tip;
  for (std::size_t k = 0; k < sh.size(); ++k)
    if (sh.reference(k).x() > L - dx) tip.push_back(k);
  const double T = 1 / f1;
  const int chunks = 400;
  for (int c = 1; c <= chunks; ++c) {
    const double top = std::getenv("ROLL_TOP") ? std::atof(std::getenv("ROLL_TOP")) : 1.0;
    const double time = 8 * T * c / chunks, ramp = top * std::min(1.0, time / (6 * T));
    // A conservative end moment: the generalised force of the potential -M theta(d), theta = atan2(-d_x, d_z)
    // the director's turn about -y, i.e. tau = d x (M dtheta/dd) = M (d_y d_x, -(d_x^2 + d_z^2), d_y d_z) /
    // (d_x^2 + d_z^2). (A constant moment vector on a director that leaves the plane is not conservative.)
    // Updated after every step.
    auto apply = [&] {
      for (std::size_t k : tip) {
        const Vec3 d = sh.director(k);
        const double r2 = d.x() * d.x() + d.z() * d.z();
        sh.set_external_moment(
            k, ramp * M / static_cast<double>(tip.size()) / r2 * Vec3(d.y() * d.x(), -r2, d.y() * d.z()));
      }
    };
    apply();
    w.advance_to(time, [&] {
      // Diagnostic (docs/validation.md): ROLL_PLANAR=1 keeps the directors in the bending plane (d_y = 0).
      if (std::getenv("ROLL_PLANAR"))
        for (std::size_t k = 0; k < sh.size(); ++k) {
          Vec3 d = sh.director(k);
          d.y() = 0;
          sh.set_director(k, d);
        }
      apply();
      return true;
    });
    if (c % 40 == 0) {
      Vec3 tx = Vec3::Zero();
      for (std::size_t k : tip) tx += w.particles().x[sh.at(k)] / static_cast<double>(tip.size());
      // Pure bending of the exact solution: kappa = ramp 2 pi / L, tip at (sin(kappa L) / kappa, (1 - cos) /
      // kappa).
      const double kap = ramp * 2 * std::numbers::pi / L;
      WARN("roll-up t = " << time << " moment " << ramp << " M: tip " << tx.transpose() << ", exact "
                          << std::sin(kap * L) / kap << " " << (1 - std::cos(kap * L)) / kap);
    }
  }
  Vec3 tip_x = Vec3::Zero(), root = Vec3(0, 0, 0);
  for (std::size_t k : tip) tip_x += w.particles().x[sh.at(k)] / static_cast<double>(tip.size());
  const double gap = (tip_x - Vec3(root.x(), tip_x.y(), root.z())).norm();
  WARN("roll-up: tip at " << tip_x.transpose() << ", distance from the root " << gap << " = " << gap / L
                          << " L, " << w.steps() << " steps, " << sh.size() << " particles");
  CHECK(gap < 0.05 * L);
}

TEST_CASE(
    "shell validation: a plate strip (periodic across its width) under an end moment 2 pi E I / L rolls "
    "into a circle",
    "[.shell-validation]") {
  roll_up(2.0, true);
}

TEST_CASE("shell validation: a cantilever strip under an end moment 2 pi E I / L rolls into a circle",
          "[.shell-validation]") {
  roll_up(1.0, false);
}

TEST_CASE("shell validation: Scordelis-Lo roof, mid free-edge vertical displacement 0.3024",
          "[.shell-validation]") {
  // R = 25, L = 50, 80 degrees, t = 0.25, E = 4.32e8, nu = 0, gravity load 90 per area (rho 36, g 10); the
  // curved ends on rigid diaphragms (MacNeal & Harder 1985: held across the axis, free along it, and the
  // rotation about the axis held), the long edges free. 17 particles on the arc, 25 rows along (the end rows
  // on the diaphragms at x = +-25). Damped to static.
  // The benchmark is linear. This model is not (Green-Lagrange strain, large rotations): at the full load the
  // free edge sinks 1.2 t; the response there is within 0.5 % of the linear one but creeps to static over
  // tens of seconds, against 2.5 s at 1 % of the load (docs/validation.md "Shells"); so the load is 1 % of
  // the benchmark's and the displacements are scaled back. Diagnostics: ROOF_DIV (rows along: 24), ROOF_LOAD
  // (the load's scale: 0.01), ROOF_SOFT (directors of the end rows free), ROOF_END (simulated time),
  // ROOF_DAMPING, ROOF_HG, ROOF_MAXDT (the World's step), ROOF_PROFILE (a file for the mid-span profile,
  // "deg uz" per line).
  const double R = 25, Lr = 50, dx = Lr / (std::getenv("ROOF_DIV") ? std::atof(std::getenv("ROOF_DIV")) : 24);
  Scene s;
  s.name = "roof";
  s.spacing = dx;
  const double load = std::getenv("ROOF_LOAD") ? std::atof(std::getenv("ROOF_LOAD")) : 0.01;
  s.gravity = Vec3(0, 0, -10 * load);
  s.domain = {Vec3(-40, -40, -40), Vec3(40, 40, 40)};
  s.max_dt = std::getenv("ROOF_MAXDT") ? std::atof(std::getenv("ROOF_MAXDT")) : 1.0;  // the World's step
  s.cfl = 0.5;
  Material m = shell_material(4.32e8, 0.0, 0.25, 36.0);
  m.shell_damping = std::getenv("ROOF_DAMPING") ? std::atof(std::getenv("ROOF_DAMPING")) : 12.0;
  if (std::getenv("ROOF_HG")) m.hourglass = std::atof(std::getenv("ROOF_HG"));  // diagnostic
  s.materials = {m};
  s.bodies = {cylindrical_panel("roof", 0, R, Vec3::UnitX(), Lr + dx, 80)};
  World w(s);
  Shells& sh = w.shells_for_test();
  for (std::size_t k = 0; k < sh.size(); ++k)
    if (std::abs(sh.reference(k).x()) > 0.5 * Lr - 0.25 * dx)
      sh.set_support(k, std::getenv("ROOF_SOFT") ? 3 : 4, Vec3::UnitX());
  // The mid free edge: the particle nearest (0, R sin 40, R cos 40 - R).
  const double th = 40 * std::numbers::pi / 180;
  const std::size_t probe = nearest(w, Vec3(0, R * std::sin(th), R * std::cos(th) - R));
  const double end = std::getenv("ROOF_END") ? std::atof(std::getenv("ROOF_END")) : 3.0;
  double prev = 0.0, change = 0.0;
  for (int c = 1; c <= 6; ++c) {
    w.advance_to(end * c / 6, [] { return true; });
    const double uz = (w.particles().x[probe].z() - w.particles().x0[probe].z()) / load;
    change = uz - prev;
    WARN("roof t = " << w.time() << ": uz = " << uz << " (change " << change << "), steps " << w.steps());
    prev = uz;
  }
  const double uz = prev;
  CHECK(std::abs(change) < 1e-4 * std::abs(uz));  // static
  // The mid-span section's profile uz(angle). The sheet's free edge is half a spacing beyond the outermost
  // row (each particle carries the area around it), so the edge value is the profile's linear extrapolation
  // from the two outer rows to 40 deg; on the continuum solution that extrapolation is within 0.5 % of the
  // edge value at this spacing.
  const Particles& P = w.particles();
  std::vector<std::pair<double, double>> prof;
  for (std::size_t i = 0; i < P.size(); ++i)
    if (std::abs(P.x0[i].x()) < 1e-6 && P.x0[i].y() > 0)
      prof.emplace_back(std::atan2(P.x0[i].y(), P.x0[i].z() + R) * 180 / std::numbers::pi,
                        (P.x[i].z() - P.x0[i].z()) / load);
  std::sort(prof.begin(), prof.end());
  REQUIRE(prof.size() >= 2);
  if (const char* path = std::getenv("ROOF_PROFILE")) {
    std::ofstream f(path);
    for (const auto& [a, u] : prof) f << a << " " << u << "\n";
  }
  const auto& p1 = prof[prof.size() - 2];
  const auto& p2 = prof.back();
  const double edge = p2.second + (40 - p2.first) * (p2.second - p1.second) / (p2.first - p1.first);
  // The continuum's linear solution at the outermost row's angle: scripts/scordelis_lo_reference.py
  // (Sanders-Koiter, Ritz; 0.3006 at the edge), uz at 30, 30.5, ..., 40 deg, interpolated.
  const double ref[21] = {0.19206, 0.19780, 0.20352, 0.20921, 0.21488, 0.22052, 0.22612,
                          0.23170, 0.23723, 0.24273, 0.24819, 0.25361, 0.25900, 0.26434,
                          0.26964, 0.27490, 0.28012, 0.28530, 0.29044, 0.29554, 0.30060};
  const double pos = std::clamp((p2.first - 30) / 0.5, 0.0, 19.999);
  const int k = static_cast<int>(pos);
  const double ref_at = ref[k] + (pos - k) * (ref[k + 1] - ref[k]);
  std::ostringstream os;
  for (const auto& [a, u] : prof) os << a << ":" << u << " ";
  WARN("Scordelis-Lo mid-span profile (deg:uz) " << os.str());
  WARN("Scordelis-Lo: outermost row at "
       << p2.first << " deg: uz = " << p2.second << " (the probe's " << uz << "), continuum there " << -ref_at
       << ", ratio " << -p2.second / ref_at << "; extrapolated to the edge " << edge << ", ratio to 0.3024 "
       << -edge / 0.3024 << ", " << sh.size() << " particles");
  CHECK(-edge == Approx(0.3024).epsilon(0.05));
  CHECK(-p2.second == Approx(ref_at).epsilon(0.05));
}
