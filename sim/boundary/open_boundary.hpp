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
//   - Fluid particles that flow backwards more than one spacing into a velocity inlet's buffer are removed
//     (counted as volume out).
//   - Pressure inlet (an inflow given `pressure` instead of `velocity`, issue 17): pressure Dirichlet,
//     velocity Neumann, the outflow's treatment mirrored across the disc. The buffer is laid on the lattice
//     as a velocity inlet's; its particles take the prescribed p(t) plus the hydrostatic difference (density
//     from the equation of state, mass rho dx^3 as a velocity inlet's), and their velocity is carried from
//     the fluid next to the disc through the buffer (normal component, layer by layer, nearest the disc
//     first, as at an outflow). A buffer particle that crosses the disc becomes fluid; fluid that crosses
//     the disc backwards (diastolic backflow) becomes a buffer particle (counted as volume out) and is
//     removed when it passes the buffer's far face. Every lattice column is topped up to `layers` particles
//     after each step (refill_columns in the .cpp).
//   - Windkessel outlet (an outflow given `windkessel`): the outlet's p(t) is the RCR model's
//     (sim/physiology/windkessel.hpp), advanced every step with the flow Q out of the domain at that step.
//   - Flow through each boundary (for the Windkessel and the `open_boundary` probe), positive in the
//     boundary's direction (into the domain at an inflow, out of it at an outflow): the volume flux of the
//     fluid in a slab one kernel support deep on the domain's side of the disc, Q = sum_i V_i (v_i . n)
//     w(d_i) / (L / 2), d the distance from the disc, L = 2h, w(d) = sin^2(pi d / L) (a smooth window:
//     particles enter and leave the slab with zero weight, so Q has no jumps when they do; integral of w over
//     the slab: L / 2). Probes report its time average over the steps since the last output time (a multiple
//     of time.output_interval).
//   - Non-reflecting treatment (a boundary given `non_reflecting: {relaxation_time: tau}`, issue 17 item 3):
//     the Dirichlet conditions above reflect every acoustic wave that reaches them (a prescribed pressure
//     with inversion, a prescribed velocity like a rigid end), so the column between an inlet and an outlet
//     rings at its organ-pipe frequencies. With the treatment, the boundary lets the outgoing plane wave
//     (p' = rho0 c0 u'_n travelling out of the domain) pass and holds the prescribed value only on average,
//     relaxing toward it with the time constant tau: the partially non-reflecting condition of Rudy &
//     Strikwerda 1980 (J. Comput. Phys. 36:55) in the linearised characteristic (LODI) form of Poinsot & Lele
//     1992 (J. Comput. Phys. 101:104, eq. 40 with K = 1 / tau). Pressure-driven boundaries impose
//     p = p_target(t) + p_w, with dp_w/dt = s rho0 c0 du/dt - p_w / tau, u the mean normal velocity of the
//     fluid in the slab next to the disc (the flow window below) and s = +1 at an outflow (normal out of the
//     domain), -1 at a pressure inlet (normal into it); a velocity inlet imposes u_n = V(t) f(r) - p_w /
//     (rho0 c0) (not below 0), with dp_w/dt = dp/dt - p_w / tau, p the inlet slab's mean pressure. For a wave
//     of angular frequency omega the reflection coefficient is |R| = 1 / sqrt(1 + (2 omega tau)^2) (Selle,
//     Nicoud & Poinsot 2004, AIAA J. 42:958): waves faster than 1 / (2 tau) leave, slower changes see the
//     prescribed value. Each step p_w advances exactly for du (dp) constant over the step:
//     p_w <- exp(-dt / tau) p_w + s rho0 c0 (u(t + dt) - u(t)).
//
// Every change of role, creation and removal is decided per particle and applied in one serial pass in index
// order, new particles are appended in that order with ids from a counter: runs stay bitwise reproducible for
// any thread count, ids stay unique.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
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

// Per open boundary (in scene order): the flow through it, its pressure and its Windkessel state. Plain
// values (for checkpoints).
struct OpenBoundaryFlow {
  double flow = 0.0;             // Q of the last step, positive in the boundary's direction [m^3/s]
  double interval_volume = 0.0;  // integral of Q dt since OpenBoundaries::interval_start() [m^3]
  double pressure = 0.0;         // the pressure it imposes now [Pa] (velocity inlet: the slab's mean)
  WindkesselState windkessel;    // Windkessel outlets only
  // Non-reflecting boundaries only: the last measured disc velocity u (pressure-driven) or slab pressure p
  // (velocity inlet), and the wave part p_w of the imposed pressure (velocity inlet: of the slab's pressure).
  double wave_ref = 0.0;
  double wave_p = 0.0;
};

// What OpenBoundaries::update did to the particle set.
struct OpenBoundaryChange {
  std::size_t created = 0;  // particles appended at the end of the arrays
  bool rebuild = false;     // the caller must rebuild its neighbour lists (particles removed, or created
                            // where a fluid particle could reach them before the lists' next rebuild)
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
  // nb: the neighbour lists of this step (still valid: nothing has moved more than half the skin).
  // Buffers deeper than the lists' reach (set_list_reach; issue 18 item 1) change the particle set without a
  // rebuild: a particle created at a buffer's far face is appended (the caller gives it an empty row until
  // its next rebuild), and a particle that leaves past a far face is not removed but "departed": its mass
  // and velocity are set to 0, so it takes part in no sum, and it waits for the caller's next list build
  // (take_departed). Neither can come within a kernel support of a fluid particle before then: the buffer
  // lies between them, at least support + skin deep. Elsewhere (shallow buffers, a particle leaving a
  // buffer sideways, backflow removed at a velocity inlet) particles are removed at once and the change asks
  // for a rebuild.
  OpenBoundaryChange update(Particles& P, const NeighborSearch& nb, const CubicSpline& K, const Vec3& gravity,
                            double t_new, double dt);

  // The caller's neighbour-list search radius (kernel support + Verlet skin) [m]; unset, every change of the
  // particle set asks for a rebuild.
  void set_list_reach(double r) { list_reach_ = r; }
  // A buffer particle that left past a far face and waits for removal (see update()).
  static bool departed(const Particles& P, std::size_t i) {
    return P.m[i] == 0.0 && (P.kind[i] == Kind::Inflow || P.kind[i] == Kind::Outflow);
  }
  // The order that drops the departed particles, the others keeping theirs (for the caller's permute, just
  // before a neighbour-list build), counted as removed; empty when none departed.
  std::vector<uint32_t> take_departed(const Particles& P);

  // Sum over inflows of the prescribed volume flow rate V(t) A [m^3/s], A = the inlet's particle columns
  // times spacing^2 (the cross-section that the particles really feed).
  double prescribed_inflow_rate(double t) const;

  // The pressure gauge of the `open_boundaries` rule (docs/model.md, "Pressure gauge"): the lowest pressure
  // that a boundary imposes now (pressure inlets, outflows: flows()[k].pressure), less its fluid's background
  // pressure, and never below 0; 0 without such a boundary.
  double pressure_gauge() const;

  const OpenBoundaryState& state() const { return state_; }
  OpenBoundaryState& state() { return state_; }

  // Per boundary, in scene order (checkpoints restore them with interval_start()).
  const std::vector<OpenBoundaryFlow>& flows() const { return flows_; }
  std::vector<OpenBoundaryFlow>& flows() { return flows_; }
  // Whether some boundary has the non-reflecting treatment (its wave state is then checkpointed).
  bool non_reflecting() const {
    for (const Zone& z : zones_)
      if (z.spec.non_reflecting_tau > 0.0) return true;
    return false;
  }
  double interval_start() const { return interval_start_; }
  double& interval_start() { return interval_start_; }
  // Mean flow through boundary k over the steps since interval_start() up to time t (the last step's flow
  // where no step has passed since) [m^3/s].
  double mean_flow(std::size_t k, double t) const {
    const double span = t - interval_start_;
    return span > 0.0 ? flows_[k].interval_volume / span : flows_[k].flow;
  }

 private:
  struct Zone {
    OpenBoundarySpec spec;
    Vec3 u = Vec3::Zero(), v = Vec3::Zero();  // (u, v, normal) orthonormal
    double depth = 0.0;                       // layers * spacing
    double area = 0.0;                        // inflow: columns * spacing^2
    double profile_mean = 1.0;                // inflow: mean of 1 - r^2 / R^2 over the columns
    int material = 0;                         // material of the fed body (outflow: the first fluid's)
    std::vector<Vec3> columns;                // inflow: lattice points of the columns on the disc
    int column_nr = 0;                        // inflow: the lattice's half-width in columns
    std::vector<int32_t> column_index;        // inflow: (j + nr) 2 nr + (i + nr) -> index in columns, or -1
    // Coordinates of x relative to the disc: along the normal, and distance from the axis.
    double axial(const Vec3& x) const { return (x - spec.point).dot(spec.normal); }
    double radial(const Vec3& x) const {
      const Vec3 r = x - spec.point;
      return (r - r.dot(spec.normal) * spec.normal).norm();
    }
    // The cell of side `side` of the disc's (u, v) lattice that x lies behind (or in front of).
    std::pair<int, int> cell(const Vec3& x, double side) const {
      const Vec3 r = x - spec.point;
      return {static_cast<int>(std::floor(r.dot(u) / side)), static_cast<int>(std::floor(r.dot(v) / side))};
    }
    double inflow_speed(const Vec3& x, double t) const;
    // Pressure inlet or outflow: the pressure is prescribed, the velocity carried from the fluid.
    bool pressure_driven() const { return spec.type == OpenBoundaryType::Outflow || spec.pressure_inlet; }
  };
  // Whether zone z's buffer is deep enough that particles created at or leaving past its far face need no
  // rebuild (update()): the fluid nearest the far face (a velocity inlet lets backflow a spacing deep)
  // stays farther than the lists' reach, with a tenth of a spacing for the step's motion.
  bool defers(const Zone& z) const {
    const bool velocity_inlet = z.spec.type == OpenBoundaryType::Inflow && !z.spec.pressure_inlet;
    return z.depth >= list_reach_ + (velocity_inlet ? 1.1 : 0.1) * dx_;
  }

  // A new buffer particle of the given kind at x (a new id), with the state (velocity, density, pressure,
  // mass, body, material) of particle src if given, else zero. Returns its index.
  std::size_t append_buffer_particle(Particles& P, const Vec3& x, Kind kind, std::optional<std::size_t> src);
  // Drops the pressure inlets' columns that pass within kColumnClearance spacings of a body (see the .cpp).
  void clear_columns(const Particles& P);
  // Inflow zone z's column_index, area and profile_mean from its columns (see the .cpp).
  void index_columns(Zone& z) const;
  // Inflow zone z's lattice column that holds x (its lateral position), or -1.
  int column_of(const Zone& z, const Vec3& x) const;
  // Pressure inlet k: tops up every column of its buffer to `layers` particles (see the .cpp).
  void refill_columns(Particles& P, std::size_t k, std::size_t n, const std::vector<uint8_t>& action,
                      std::size_t& created, bool& rebuild);
  // Every outflow particle (of the first n) takes the fluid's normal velocity at the disc (see the .cpp).
  void carry_disc_velocity(Particles& P, const CubicSpline& K, std::size_t n) const;
  // Index of the zone whose buffer holds particle x of the given kind, or -1.
  int zone_of(const Vec3& x, Kind kind) const;
  // Pressure and density of every buffer particle at time t (records each boundary's pressure in flows_).
  void impose(Particles& P, const Vec3& gravity, double t);
  // Per zone, the window sums of the slab next to its disc (see above): sum V (v . n) w and sum V w.
  struct SlabSums {
    double flux = 0.0, weight = 0.0;
  };
  std::vector<SlabSums> slab_sums(const Particles& P) const;
  // The flow through a boundary (see above) from its slab sums.
  double slab_flow(const SlabSums& s) const;
  // The prescribed pressure of a pressure inlet or an outflow at time t.
  double prescribed_pressure(std::size_t k, double t) const;
  // Mean normal velocity of the fluid next to a disc (the window-weighted v . n; 0 in an empty window), used
  // by the pressure-driven non-reflecting boundaries.
  static double slab_velocity(const SlabSums& s);

  std::vector<Zone> zones_;
  std::vector<FluidParams> fluid_;
  double dx_ = 0.0;
  double support_ = 0.0;
  double row_interval_ = 0.0;  // the probe rows' interval: each row's flow is the mean since the last row
  double list_reach_ = std::numeric_limits<double>::infinity();
  OpenBoundaryState state_;
  std::vector<OpenBoundaryFlow> flows_;
  double interval_start_ = 0.0;
};

}  // namespace aortasph
