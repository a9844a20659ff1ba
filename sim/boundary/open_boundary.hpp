// Open boundaries: an inflow that creates fluid particles with a prescribed velocity, and an outflow with a
// prescribed pressure that removes them. Buffer-zone method in the style of Federico, Marrone, Colagrossi,
// Aristodemo & Veltri 2012, "Simulating 2D open-channel flows through an SPH model", Eur. J. Mech. B/Fluids
// 34:35-46, and Tafuni, Dominguez, Vacondio & Crespo 2018, "A versatile algorithm for the treatment of open
// boundary conditions in Smoothed particle hydrodynamics GPU models", Comput. Methods Appl. Mech. Engrg.
// 342:604-624:
//
//   - Each open boundary is a disc (centre `point`, unit `normal`, `radius`) with a buffer cylinder of
//     `layers` particle layers behind it (inflow: upstream of the disc, outside the domain; outflow:
//     downstream). Buffer particles (Kind::Inflow, Kind::Outflow) enter the fluid's sums like fluid
//     particles, so the fluid next to the disc has a full kernel support; but their state is set here, not
//     integrated.
//   - Inflow (velocity Dirichlet, pressure Neumann): buffer particles move with the prescribed velocity
//     V(t) f(r) n (f = 1, or a Poiseuille profile scaled so that its mean over the inlet's particle columns
//     is 1); their pressure is the mean fluid pressure in a slab one kernel support deep inside the disc
//     (zero gradient along the axis) plus the hydrostatic difference, and their density follows from the
//     equation of state. A buffer particle that crosses the disc becomes a fluid particle, and a new buffer
//     particle is created `layers` spacings behind it, in the same lattice column (the lattice feeds on
//     without gaps).
//   - Outflow (pressure Dirichlet, velocity Neumann): a fluid particle that crosses the disc becomes an
//     outflow particle. Its pressure is the prescribed p(t) plus the hydrostatic difference, its density
//     from the equation of state; its velocity is carried through the buffer from the fluid (normal component
//     of the Shepard average of the fluid neighbours and of the outflow neighbours nearer the disc, layer by
//     layer). It is removed
//     when it passes the buffer's far face. If it returns across the disc (backflow) it turns back into
//     fluid and a new outflow particle is created `layers` spacings further out, so the buffer stays full
//     through back-and-forth flow.
//   - Fluid particles that flow backwards more than one spacing into an inflow buffer are removed (counted as
//     volume out).
//
// Every change of role, creation and removal is decided per particle and applied in one serial pass in index
// order, new particles are appended in that order with ids from a counter: runs stay bitwise reproducible for
// any thread count, ids stay unique.
#pragma once

#include <cstdint>
#include <vector>

#include "core/kernel.hpp"
#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "fluid/fluid_wcsph.hpp"
#include "scene.hpp"

namespace aortasph {

// The mutable state of the open boundaries beyond the particles themselves: plain values (for checkpoints).
struct OpenBoundaryState {
  uint32_t next_id = 0;     // id of the next particle created
  double volume_in = 0.0;   // cumulative volume that entered the domain (m / rho at the crossing) [m^3]
  double volume_out = 0.0;  // cumulative volume that left it through an open boundary [m^3]
  double mass_in = 0.0;     // the same as masses [kg]
  double mass_out = 0.0;
  uint64_t created = 0;  // particles created (inflows feeding, outflows refilled after backflow)
  uint64_t removed = 0;  // particles removed at outflows and inflows
};

class OpenBoundaries {
 public:
  OpenBoundaries() = default;

  // Adds the inflow buffer particles (ids from the largest id + 1), turns fluid particles already inside an
  // outflow buffer into outflow particles, and imposes the buffers' state at time 0. Throws SetupError where
  // a buffer overlaps a body or lies outside the domain. fluid: per-material parameters (World::fluid_).
  void setup(const Scene& scene, const std::vector<FluidParams>& fluid, Particles& P);

  // Only the read-only part of setup() (geometry, lattice columns, checks), no particle and no state: for a
  // world restored from a checkpoint, whose particles already hold the buffers; restore state() after it.
  void configure(const Scene& scene, const std::vector<FluidParams>& fluid);

  bool empty() const { return zones_.empty(); }

  // The stage of the step, after the fluid has been integrated to t_new = t + dt: buffers move, particles
  // that crossed a disc change role, are created or removed, and the buffers' state is imposed for t_new.
  // nb: the neighbour lists of this step (still valid: nothing has moved more than half the skin). Returns
  // true when particles were created or removed (the caller must rebuild its neighbour lists).
  bool update(Particles& P, const NeighborSearch& nb, const CubicSpline& K, const Vec3& gravity, double t_new,
              double dt);

  // Sum over inflows of the prescribed volume flow rate V(t) A [m^3/s], A = the inlet's particle columns
  // times spacing^2 (the cross-section that the particles really feed).
  double prescribed_inflow_rate(double t) const;

  const OpenBoundaryState& state() const { return state_; }
  OpenBoundaryState& state() { return state_; }

 private:
  struct Zone {
    OpenBoundarySpec spec;
    Vec3 u = Vec3::Zero(), v = Vec3::Zero();  // (u, v, normal) orthonormal
    double depth = 0.0;                       // layers * spacing
    double area = 0.0;                        // inflow: columns * spacing^2
    double profile_mean = 1.0;                // inflow: mean of 1 - r^2 / R^2 over the columns
    int material = 0;                         // inflow: material of the fed body
    std::vector<Vec3> columns;                // inflow: lattice points of the columns on the disc
    // Coordinates of x relative to the disc: along the normal, and distance from the axis.
    double axial(const Vec3& x) const { return (x - spec.point).dot(spec.normal); }
    double radial(const Vec3& x) const {
      const Vec3 r = x - spec.point;
      return (r - r.dot(spec.normal) * spec.normal).norm();
    }
    double inflow_speed(const Vec3& x, double t) const;
  };

  // Index of the zone whose buffer holds particle x of the given kind, or -1.
  int zone_of(const Vec3& x, Kind kind) const;
  // Pressure and density of every buffer particle at time t.
  void impose(Particles& P, const Vec3& gravity, double t) const;

  std::vector<Zone> zones_;
  std::vector<FluidParams> fluid_;
  double dx_ = 0.0;
  double support_ = 0.0;
  OpenBoundaryState state_;
};

}  // namespace aortasph
