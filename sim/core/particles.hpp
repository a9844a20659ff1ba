// Particle storage as a structure of arrays: hot state (x, v, a, rho, p) in contiguous arrays, so the
// neighbour loops stream through memory. permute() reorders every per-particle array at once after a spatial
// sort, so no array can forget to follow.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "scene.hpp"

namespace aortasph {

// Inflow and Outflow: fluid particles in the buffer of an open boundary (sim/boundary/open_boundary.hpp).
// They enter the fluid's sums like fluid particles, but their velocity, density and pressure are imposed or
// extrapolated by the open boundary instead of being integrated.
// Shell: a particle of a one-layer shell's mid-surface (sim/solid/shell.hpp).
enum class Kind : uint8_t { Fluid = 0, Wall = 1, Rigid = 2, Elastic = 3, Inflow = 4, Outflow = 5, Shell = 6 };

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
  // Particle shifting (fluid/shifting.hpp): each particle's shift of the last step, applied in
  // World::integrate and counted in the next step's density (fluid_density_rate). Optional: empty when no
  // fluid shifts, and resize() and permute() leave it empty then.
  std::vector<Vec3> shift;

  std::size_t size() const { return x.size(); }

  // Calls f(name, array) for every per-particle array: the one list that resize(), permute() and the
  // checkpoint (World::save_state) follow, so a new array added here is sorted, removed and saved with the
  // rest.
  template <class F>
  void for_each_array(F&& f) {
    f("x", x);
    f("v", v);
    f("a", a);
    f("rho", rho);
    f("drho", drho);
    f("p", p);
    f("v_wall", v_wall);
    f("m", m);
    f("x0", x0);
    f("kind", kind);
    f("body", body);
    f("material", material);
    f("id", id);
    f("shift", shift);
  }
  // An array that may be empty (switched off) while the others hold every particle.
  static bool optional(const char* name) { return std::strcmp(name, "shift") == 0; }
  template <class F>
  void for_each_array(F&& f) const {
    const_cast<Particles*>(this)->for_each_array(
        [&](const char* name, const auto& array) { f(name, array); });
  }

  void resize(std::size_t n) {
    // New entries are zero (Kind::Fluid for kind).
    for_each_array([n](const char* name, auto& array) {
      if (optional(name) && array.empty()) return;
      using T = typename std::decay_t<decltype(array)>::value_type;
      if constexpr (std::is_same_v<T, Vec3>)
        array.resize(n, Vec3::Zero());
      else
        array.resize(n, T{});
    });
  }

  // New order: particle k of the result is particle order[k] of the current arrays. order may be shorter
  // than size() (particles left out are removed).
  void permute(const std::vector<uint32_t>& order) {
    for_each_array([&order](const char* name, auto& array) {
      if (!(optional(name) && array.empty())) apply(array, order);
    });
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
