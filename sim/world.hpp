// World: the particles and bodies of one scene, and the time step that advances them.
// The scene (materials, parameters) is read-only after construction; step() only writes state.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "boundary/mask_density.hpp"
#include "boundary/open_boundary.hpp"
#include "boundary/shell_coupling.hpp"
#include "core/kernel.hpp"
#include "core/neighbors.hpp"
#include "core/particles.hpp"
#include "fluid/fluid_wcsph.hpp"
#include "fluid/volume_check.hpp"
#include "geometry/shapes.hpp"
#include "io/checkpoint.hpp"
#include "io/snapshot.hpp"
#include "rigid/contact_dem.hpp"
#include "rigid/rigid_body.hpp"
#include "scene.hpp"
#include "solid/shell.hpp"
#include "solid/shell_contact.hpp"
#include "solid/shell_mesh.hpp"
#include "solid/solid_tlsph.hpp"

namespace aortasph {

// Wall time per phase of the step, summed over steps [s].
struct Profile {
  double neighbors = 0, density = 0, boundary = 0, forces = 0, solid = 0, rigid = 0, integrate = 0,
         open_boundary = 0, sort = 0;
  double total() const {
    return neighbors + density + boundary + forces + solid + rigid + integrate + open_boundary + sort;
  }
  // (name, seconds) of each phase, in step order: the one list that diagnostics, run.json and bench print.
  std::vector<std::pair<std::string, double>> phases() const {
    return {{"neighbors", neighbors},
            {"density", density},
            {"boundary", boundary},
            {"forces", forces},
            {"solid", solid},
            {"rigid", rigid},
            {"integrate", integrate},
            {"open_boundary", open_boundary},
            {"sort", sort}};
  }
  // The same phases as writable slots, in the order of phases() (checkpoint load).
  std::array<double*, 9> slots() {
    return {&neighbors, &density, &boundary, &forces, &solid, &rigid, &integrate, &open_boundary, &sort};
  }
  Profile operator-(const Profile& o) const {
    return {neighbors - o.neighbors,
            density - o.density,
            boundary - o.boundary,
            forces - o.forces,
            solid - o.solid,
            rigid - o.rigid,
            integrate - o.integrate,
            open_boundary - o.open_boundary,
            sort - o.sort};
  }
};

struct BodyInfo {
  std::string name;
  MaterialType type = MaterialType::Fluid;
  int material = 0;
  std::size_t count = 0;  // particles at t = 0
  int rigid = -1;         // index into World::rigid_bodies() for rigid bodies
  SurfaceMesh mesh;       // world coordinates at t = 0
};

class World {
 public:
  // Samples every body, sets masses, densities (hydrostatic for fluids under gravity) and velocities.
  // Throws SetupError when the scene cannot be built (empty body, overlapping bodies, unsupported model).
  explicit World(const Scene& scene);

  // Sets the velocity of every moving particle of a body that is not clamped to v(x0), before the first step
  // (initial conditions that a uniform body velocity cannot express: a mode shape, a pulse). Not for rigid
  // bodies, whose particles follow the body.
  template <class VelocityOf>
  void set_initial_velocity(int body, VelocityOf&& v_of_x0) {
    for (std::size_t i = 0; i < P_.size(); ++i) {
      if (P_.body[i] != body || P_.kind[i] == Kind::Wall || P_.kind[i] == Kind::Rigid) continue;
      const long s = solids_.slot(i);
      if (s >= 0 && solids_.clamped(static_cast<std::size_t>(s))) continue;
      const long sh = shells_.slot(i);
      if (sh >= 0 && shells_.support(static_cast<std::size_t>(sh)) != 0) continue;
      P_.v[i] = v_of_x0(P_.x0[i]);
      max_speed_ = std::max(max_speed_, P_.v[i].norm());
      if (sh >= 0 && !sub_.v.empty()) sub_.v[static_cast<std::size_t>(sh)] = P_.v[i];
    }
  }

  // Largest stable time step now: acoustic CFL, viscous and force limits (Monaghan 1992; Morris et al. 1997)
  // and the scene's max_dt.
  double stable_dt() const;

  // One step of length dt (Algorithm 1). Throws InstabilityError on NaN/Inf, a speed over the limit, a
  // density error over time.max_density_error or particles leaving the domain beyond the allowed fraction.
  void step(double dt);

  // Advance to exactly t_target in equal steps (SPEC: outputs at exact times). on_step() is
  // called after each step (progress, interruption); returning false stops early. Returns whether t_target
  // was reached.
  template <class OnStep>
  bool advance_to(double t_target, OnStep&& on_step) {
    while (time_ < t_target) {
      // The rest of the interval in equal steps no longer than the stable one: no shortened last step. A
      // short step at every output time, repeated every few dozen steps, pumps energy into modes near half
      // that repeat frequency (an undamped TL-SPH beam with outputs every 55 steps gained 500x its energy).
      const double remaining = t_target - time_;
      const double steps_left = std::ceil(remaining / stable_dt() * (1.0 - 1e-12));
      const bool last = steps_left <= 1.0;
      const double dt = last ? remaining : remaining / steps_left;
      step(dt);
      if (last) time_ = t_target;
      if (!on_step()) return time_ >= t_target;
    }
    return true;
  }

  const Scene& scene() const { return scene_; }
  const Particles& particles() const { return P_; }
  const NeighborSearch& neighbors() const { return nb_; }
  const FluidContext& fluid_context() const { return ctx_; }
  const std::vector<BodyInfo>& bodies() const { return bodies_; }
  const std::vector<RigidBody>& rigid_bodies() const { return rigid_; }
  const Solids& solids() const { return solids_; }
  // Mass that moves particle i [kg]: an elastic particle's own mass; for others the mass of the fluid sums
  // (rigid particles' mass lives in their RigidBody).
  double inertial_mass(std::size_t i) const {
    const long s = solids_.slot(i);
    if (const long sh = shells_.slot(i); sh >= 0) return shells_.mass(static_cast<std::size_t>(sh));
    return s >= 0 ? solids_.mass(static_cast<std::size_t>(s)) : P_.m[i];
  }
  const Shells& shells() const { return shells_; }
  // The shell bodies' sheets: triangles by shell slot, built once at t = 0 (solid/shell_mesh.hpp).
  const ShellSheets& shell_sheets() const { return sheets_; }
  // Fluid on both sides of the shells (sim/boundary/shell_coupling.hpp): fluid particles put back on their
  // side of a sheet since t = 0 (0 when the coupling holds), and the pairs masked in the last step.
  long shell_crossings() const { return coupling_.crossings(); }
  // The put-backs of the last step, each with its particle, place, body and depth (ShellCoupling::PutBack).
  const std::vector<ShellCoupling::PutBack>& last_shell_put_backs() const {
    return coupling_.last_put_backs();
  }
  long shell_label_disagreements() const { return coupling_.label_disagreements(); }
  // The side of shell body `body` on which the last step found particle i (ShellCoupling::side).
  int shell_side(uint32_t i, uint16_t body) const { return coupling_.side(i, body); }
  // Shell sub-cycling (World::step_shells): shell sub-steps taken since t = 0, the number in the last step,
  // and the shells' own leapfrog velocities by shell slot (P.v of a shell particle is its mean over the
  // step, what the fluid sees).
  long shell_substeps() const { return sub_.substeps; }
  int last_shell_substeps() const { return sub_.last_n; }
  const std::vector<Vec3>& shell_velocities() const { return sub_.v; }
  // The shells' own stable step (plate wave, shear-rotary, force limit): the sub-step bound.
  double shell_stable_dt() const;
  std::size_t shell_masked_pairs() const { return coupling_.masked_pairs(); }
  // Shell particles on the rim of a free edge (their imaginary particles slide over the half spacing beyond
  // them: fluid/shell_wall.hpp).
  std::size_t shell_rim_particles() const { return coupling_.rim_particles(); }
  Shells& shells_for_test() { return shells_; }
  const CubicSpline& kernel() const { return kernel_; }
  const std::vector<FluidParams>& fluid_params() const { return fluid_; }
  const Profile& profile() const { return profile_; }
  const OpenBoundaries& open_boundaries() const { return open_; }
  double time() const { return time_; }
  long steps() const { return steps_; }
  double last_dt() const { return last_dt_; }
  long list_builds() const { return builds_; }
  // Whether the neighbour lists describe the current particles (false after a change of the particle set
  // that asks for a rebuild: the next step's first act).
  bool lists_current() const { return lists_valid_; }
  double max_speed() const { return max_speed_; }
  double speed_limit() const { return speed_limit_; }
  std::size_t count(Kind k) const;
  std::size_t left_domain() const { return left_domain_; }
  // max |rho / rho0 - 1| over fluid particles.
  double max_density_error() const;
  // Summation density over continuity density of the fluid with a full support (fluid/volume_check.hpp).
  VolumeCheck fluid_volume_check() const;
  // Bytes held by particle arrays and neighbour lists.
  std::size_t memory_bytes() const;

  // Checkpoint (sim/io/checkpoint.hpp): save_state() writes every piece of state that step() reads (time,
  // counters, all particle arrays, rigid bodies, the Verlet lists' build positions), so that a World built
  // from the same scene and given load_state() continues bitwise as the saved one would have. load_state()
  // throws SetupError when the checkpoint does not fit this scene. New state: add a section to both.
  void save_state(StateWriter& out) const;
  void load_state(const StateReader& in);

  // What the renderer needs, with each of `fields` (material, speed, pressure, displacement, stress)
  // computed once; "material" and repeats add nothing.
  Snapshot snapshot(const std::vector<std::string>& fields, int frame) const;
  Snapshot snapshot(const std::string& field, int frame) const;  // one field

 private:
  void update_neighbors();
  void build_lists();
  void append_to_lists(std::size_t first);  // particles first.. appended by the open boundaries
  std::vector<uint8_t> fixed_mask() const;  // 1 for particles that never move (walls)
  void integrate(double dt);
  // The velocity update's length for a step of dt (see integrate()): dt on the first step, else the mean of
  // the previous and this step.
  double kick_length(double dt) const { return last_dt_ > 0.0 ? 0.5 * (last_dt_ + dt) : dt; }
  void body_forces();
  void step_rigid(double dt);
  void step_solids();
  void step_shells(double dt);
  void shell_substep(double h, double kick, double t, const std::vector<Vec3>& held,
                     const std::vector<Vec3>* barrier);
  void add_shell_seeds(const Body& body, const std::string& where, const ShapeSample& sample,
                       std::size_t first, std::vector<ShellSeed>& seeds) const;
  void permute(const std::vector<uint32_t>& order);
  void check_and_remove(double dt);

  Scene scene_;
  CubicSpline kernel_;
  Vec3 gravity_;
  std::vector<FluidParams> fluid_;  // per material (entries of non-fluid materials unused)
  FluidParams wall_ref_;            // equation of state that boundary particles use
  FluidContext ctx_;                // refers to kernel_ and fluid_; holds per-step scratch arrays
  Particles P_;
  NeighborSearch nb_;
  std::vector<BodyInfo> bodies_;
  std::vector<RigidBody> rigid_;
  Solids solids_;
  Shells shells_;
  ShellSheets sheets_;                   // the shells' triangulated mid-surfaces (render, VTK)
  MaskDensity mask_density_;             // the density across the coupling's mask changes
  bool mask_density_on_ = false;         // a fluid material asks for it (FluidParams::mask_density)
  ShellCoupling coupling_;               // active when a scene has shells and a fluid
  std::vector<double> barrier_modulus_;  // per material, the fluid's barrier K [Pa]; empty: off
  // Shell sub-cycling state (step_shells): leapfrog velocities by shell slot (empty until the first step,
  // then filled from P.v), the last sub-step's length, the largest speed and acceleration of the last step's
  // sub-steps, and counters.
  struct ShellSubcycle {
    std::vector<Vec3> v;
    double last_h = 0.0, max_speed = 0.0, max_accel = 0.0;
    long substeps = 0;
    int last_n = 0;
  } sub_;
  OpenBoundaries open_;  // inflows and outflows; their counters are plain values (OpenBoundaryState)
  ContactParams contact_;
  double min_shell_thickness_ = std::numeric_limits<double>::max();  // the step bound under shell contact
  bool contact_in_substeps_ = false;  // shell contact evaluated in the shells' sub-steps (World::step_shells)
  std::vector<Vec3> contact_f_;       // its forces in a sub-step, by particle (shell entries only)
  ShellContact shell_contact_;  // sheets against sheets and walls (active when contact.shell_stiffness > 0)
  double min_contact_mass_ = std::numeric_limits<double>::max();
  std::vector<Vec3> force_;   // per-particle force on body particles of the current step
  bool shifting_ = false;     // some fluid material shifts its particles
  bool transport_ = false;    // some fluid material has the transport-velocity formulation
  std::vector<Vec3> moment_;  // and the moment of its contact forces about the particle (contact_dem.hpp)
  Profile profile_;
  double time_ = 0.0;
  long steps_ = 0;
  double last_dt_ = 0.0;
  double max_speed_ = 0.0;
  double max_accel_ = 0.0;
  double speed_limit_ = 0.0;
  double max_c0_ = 0.0;
  double max_nu_ = 0.0;
  std::size_t moving_at_start_ = 0;
  std::size_t left_domain_ = 0;
  // Verlet lists: built with radius support + skin, rebuilt when a particle has moved skin / 2.
  double skin_ = 0.0;
  bool lists_valid_ = false;
  long builds_ = 0;
  int sort_every_builds_ = 4;
  // Positions at the last build of the particles that can move (every kind but the fixed walls, whose
  // position never changes): x_at_build_[k] is that of particle skin_index_[k]. The checkpoint holds the
  // full array (walls at their position), as before.
  std::vector<Vec3> x_at_build_;
  std::vector<uint32_t> skin_index_;
  // Particles 0 .. listed_ - 1 are in the lists; those appended since the last build have empty rows.
  std::size_t listed_ = 0;
  void record_build_positions(const std::vector<Vec3>& x);
  void jitter_points(std::vector<Vec3>& points, std::size_t b, double amplitude) const;  // Body::jitter
  std::vector<Vec3> build_positions() const;  // every particle's, walls included
};

}  // namespace aortasph
