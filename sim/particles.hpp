// Particle storage as a structure of arrays: hot state (x, v, a, rho, p) in contiguous arrays, so the
// neighbour loops stream through memory. permute() reorders every per-particle array at once after a spatial
// sort, so no array can forget to follow.
#pragma once

#include <cstdint>
#include <vector>

#include "scene.hpp"

namespace aortasph {

// Inflow and Outflow: fluid particles in the buffer of an open boundary (sim/open_boundary.hpp). They enter
// the fluid's sums like fluid particles, but their velocity, density and pressure are imposed or extrapolated
// by the open boundary instead of being integrated.
enum class Kind : uint8_t { Fluid = 0, Wall = 1, Rigid = 2, Elastic = 3, Inflow = 4, Outflow = 5 };

// Particles that the fluid sees as fluid: fluid proper and open-boundary buffer particles.
inline bool fluid_like(Kind k) {
  return k == Kind::Fluid || k == Kind::Inflow || k == Kind::Outflow;
}

struct Particles {
  // Hot state.
  std::vector<Vec3> x;       // position [m]
  std::vector<Vec3> v;       // velocity [m/s]
  std::vector<Vec3> a;       // acceleration of this step [m/s^2]
  std::vector<double> rho;   // density [kg/m^3] (walls: extrapolated, Adami et al. 2012)
  std::vector<double> drho;  // d rho / dt of this step
  std::vector<double> p;     // pressure [Pa]
  std::vector<Vec3> v_wall;  // walls: extrapolated velocity for the no-slip condition (Adami et al. 2012)
  // Cold state.
  std::vector<double> m;  // mass [kg]
  std::vector<Vec3> x0;   // position at t = 0 (displacement, TL-SPH reference)
  std::vector<Kind> kind;
  std::vector<uint16_t> body;      // index into the scene's bodies
  std::vector<uint16_t> material;  // index into the scene's materials
  std::vector<uint32_t> id;        // creation index: stable across sorts

  std::size_t size() const { return x.size(); }

  void resize(std::size_t n) {
    x.resize(n, Vec3::Zero());
    v.resize(n, Vec3::Zero());
    a.resize(n, Vec3::Zero());
    rho.resize(n, 0.0);
    drho.resize(n, 0.0);
    p.resize(n, 0.0);
    v_wall.resize(n, Vec3::Zero());
    m.resize(n, 0.0);
    x0.resize(n, Vec3::Zero());
    kind.resize(n, Kind::Fluid);
    body.resize(n, 0);
    material.resize(n, 0);
    id.resize(n, 0);
  }

  // New order: particle k of the result is particle order[k] of the current arrays. order may be shorter
  // than size() (particles left out are removed).
  void permute(const std::vector<uint32_t>& order) {
    apply(x, order);
    apply(v, order);
    apply(a, order);
    apply(rho, order);
    apply(drho, order);
    apply(p, order);
    apply(v_wall, order);
    apply(m, order);
    apply(x0, order);
    apply(kind, order);
    apply(body, order);
    apply(material, order);
    apply(id, order);
  }

 private:
  template <class T>
  static void apply(std::vector<T>& data, const std::vector<uint32_t>& order) {
    std::vector<T> out(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = data[order[k]];
    data.swap(out);
  }
};

}  // namespace aortasph
