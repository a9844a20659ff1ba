// Small scenes built in code for the physics tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

#include "scene.hpp"
#include "world.hpp"

namespace aortasph::test {

// Smallest distance between a point of a and a point of b (hash grid of cell `reach`); reach if none closer.
inline double min_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double reach) {
  std::map<std::tuple<int, int, int>, std::vector<Vec3>> grid;
  auto key = [&](const Vec3& q) {
    return std::tuple{static_cast<int>(std::floor(q.x() / reach)),
                      static_cast<int>(std::floor(q.y() / reach)),
                      static_cast<int>(std::floor(q.z() / reach))};
  };
  for (const Vec3& q : b) grid[key(q)].push_back(q);
  double best = reach;
  for (const Vec3& q : a) {
    const auto [i, j, k] = key(q);
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) {
          const auto it = grid.find({i + di, j + dj, k + dk});
          if (it == grid.end()) continue;
          for (const Vec3& o : it->second) best = std::min(best, (o - q).norm());
        }
  }
  return best;
}

// FNV-1a hash of the whole particle state (position, velocity, density, id, kind), bit for bit: equal
// hashes, equal states (determinism and checkpoint tests).
inline uint64_t state_hash(const World& w) {
  const Particles& P = w.particles();
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* data, std::size_t bytes) {
    const auto* c = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ c[k]) * 1099511628211ull;
  };
  for (std::size_t i = 0; i < P.size(); ++i) {
    mix(P.x[i].data(), sizeof(double) * 3);
    mix(P.v[i].data(), sizeof(double) * 3);
    mix(&P.rho[i], sizeof(double));
    mix(&P.id[i], sizeof(uint32_t));
    mix(&P.kind[i], sizeof(Kind));
  }
  return h;
}

inline Material water(double c0 = 20.0) {
  Material m;
  m.name = "water";
  m.type = MaterialType::Fluid;
  m.density = 1000.0;
  m.viscosity = 1e-6;
  m.sound_speed = c0;
  return m;
}

inline Material wall() {
  Material m;
  m.name = "wall";
  m.type = MaterialType::Wall;
  return m;
}

// A one-layer shell material (sim/solid/shell.hpp) with the tests' hourglass coefficient 0.05.
inline Material shell_sheet(double E, double nu, double t, double rho = 1000.0, double damping = 0.0) {
  Material m;
  m.name = "sheet";
  m.type = MaterialType::Shell;
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.thickness = t;
  m.hourglass = 0.05;
  m.shell_damping = damping;
  return m;
}

inline Body box_body(const std::string& name, int material, Vec3 lo, Vec3 hi, Vec3 velocity = Vec3::Zero()) {
  Body b;
  b.name = name;
  b.material = material;
  b.shape.kind = ShapeKind::Box;
  b.shape.box = {lo, hi};
  b.velocity = velocity;
  return b;
}

// A cylindrical shell panel of radius R whose crown is at the origin facing +z (its axis through (0, 0, -R)).
inline Body cylindrical_panel(const std::string& name, int material, double R, Vec3 axis, double length,
                              double angle_deg) {
  Body b;
  b.name = name;
  b.material = material;
  b.shape.kind = ShapeKind::CylindricalPanel;
  b.shape.center = Vec3(0, 0, -R);
  b.shape.axis = axis;
  b.shape.radius = R;
  b.shape.length = length;
  b.shape.angle = angle_deg;
  b.shape.normal = Vec3::UnitZ();
  return b;
}

inline Body container(const std::string& name, int material, Vec3 lo, Vec3 hi,
                      std::vector<std::string> open) {
  Body b;
  b.name = name;
  b.material = material;
  b.shape.kind = ShapeKind::Container;
  b.shape.box = {lo, hi};
  b.shape.layers = 3;
  b.shape.open = std::move(open);
  return b;
}

// Two water cubes flying at each other, off-centre, no walls, no gravity (the paper's Figure 1).
inline Scene fluid_cubes(double dx) {
  Scene s;
  s.name = "cubes";
  s.spacing = dx;
  s.gravity = Vec3::Zero();
  s.domain = {Vec3(-1, -1, -1), Vec3(1, 1, 1)};
  s.t_end = 0.1;
  s.max_dt = 1e-3;
  s.materials = {water(20.0)};
  s.bodies = {box_body("left", 0, Vec3(-0.12, -0.05, -0.05), Vec3(-0.02, 0.05, 0.05), Vec3(1, 0, 0)),
              box_body("right", 0, Vec3(0.02, -0.02, -0.05), Vec3(0.12, 0.08, 0.05), Vec3(-1, 0, 0))};
  return s;
}

// Martin & Moyce (1952) dam break, column a x 2a, in a tank of length 7a (SPEC's axis convention: +y up).
inline Scene dam_break(double a, double dx, double depth) {
  Scene s;
  s.name = "dam_break_test";
  s.spacing = dx;
  s.domain = {Vec3(-0.05, -0.05, -0.05), Vec3(8 * a + 0.05, 3 * a + 0.05, depth + 0.05)};
  s.t_end = 0.2;
  s.max_dt = 1e-3;
  s.materials = {water(10.0 * std::sqrt(2.0 * 9.81 * 2.0 * a)), wall()};
  s.bodies = {box_body("column", 0, Vec3(0, 0, 0), Vec3(a, 2 * a, depth)),
              container("tank", 1, Vec3(0, 0, 0), Vec3(8 * a, 3 * a, depth), {"+y"})};
  return s;
}

// The 2-D Taylor-Green vortex at Re = U lambda / nu = 100 in a periodic box lambda x lambda x 8 dx (periodic
// in x, y and z): kinetic energy decays as exp(-4 nu k^2 t), k = 2 pi / lambda (2 nu k^2 t d with d = 2).
struct TaylorGreen {
  double lambda = 1.0, U = 1.0, nu = 0.01;
  double decay_rate() const { return 4.0 * nu * std::pow(2.0 * M_PI / lambda, 2); }
  Scene scene(int across, double c0, double pb, double delta, double shifting = 0.0) const {
    const double dx = lambda / across, depth = 8 * dx;
    Scene s;
    s.name = "taylor_green";
    s.spacing = dx;
    s.gravity = Vec3::Zero();
    s.domain = {Vec3(0, 0, 0), Vec3(lambda, lambda, depth)};
    s.periodic = {true, true, true};
    s.t_end = 1.0;
    s.max_dt = 1e-2;
    Material m = water(c0);
    m.viscosity = nu;
    m.background_pressure = pb;
    m.delta_sph = delta;
    m.shifting = shifting;
    s.materials = {m};
    Body b = box_body("fluid", 0, Vec3::Zero(), Vec3(lambda, lambda, depth));
    b.taylor_green = InitialFlow{U, lambda};
    s.bodies = {b};
    return s;
  }
};

inline double kinetic_energy(const World& w) {
  const Particles& P = w.particles();
  double e = 0;
  for (std::size_t i = 0; i < P.size(); ++i) e += 0.5 * P.m[i] * P.v[i].squaredNorm();
  return e;
}

}  // namespace aortasph::test
