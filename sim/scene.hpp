// Scene description: plain, validated values (SPEC.md section 2). No JSON here: app/scene_loader parses
// and validates the JSON file into these structs; sim/ builds a World from them; render/ reads
// RenderSettings.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "physiology/waveform.hpp"
#include "physiology/windkessel.hpp"

namespace aortasph {

using Vec3 = Eigen::Vector3d;

struct Box {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
  bool contains(const Vec3& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

enum class MaterialType { Fluid, Elastic, Rigid, Wall, Shell };

struct Material {
  std::string name;
  MaterialType type = MaterialType::Fluid;
  double density = 1000.0;  // rest density rho0 [kg/m^3] (unused for walls)

  // Fluid (weakly compressible SPH, paper section 3.1)
  double viscosity = 1e-6;            // kinematic viscosity nu [m^2/s], paper eq. (10)
  double sound_speed = 20.0;          // numerical sound speed c0 [m/s]; Tait k = rho0 c0^2 / gamma
  double eos_exponent = 7.0;          // gamma in the Tait equation, paper eq. (13)
  double delta_sph = 0.1;             // density diffusion delta (Antuono et al. 2010); 0 switches it off
  double artificial_viscosity = 0.0;  // Monaghan alpha (Monaghan 1992); 0 switches it off
  // The momentum dissipation of a low-dissipation Riemann solver (Zhang, Hu & Adams 2017): its limiter
  // eta (they use 3); 0 switches it off (sim/fluid/fluid_wcsph.cpp, pair_acceleration).
  double riemann_dissipation = 0.0;
  // Monaghan (2000)'s artificial pressure against the tensile instability: epsilon (he uses 0.2) of the
  // negative pressures; 0 switches it off (sim/fluid/fluid_wcsph.cpp, pair_acceleration).
  double tensile_correction = 0.0;
  bool density_summation = false;    // eq. (11) instead of the continuity equation (12)
  double background_pressure = 0.0;  // added to the Tait pressure [Pa]
  double shifting = 0.0;  // particle shifting coefficient A (sim/fluid/shifting.hpp); 0 switches it off
  // The shift's displacement enters the density, as the continuity equation would count it (an ALE
  // correction, sim/fluid/shifting.hpp); off by default (the physio scene with it on stopped at 79 ms, stop
  // 44).
  bool shifting_ale = false;
  // Beside shells: the density follows the summation density across the changes of the masks that keep the
  // two sides of a sheet apart (sim/boundary/mask_density.hpp); off by default (stop 54).
  bool mask_density = false;
  // Transport-velocity formulation (sim/fluid/transport_velocity.hpp): its background pressure p_b [Pa],
  // which drives the advection velocity only (unlike background_pressure above); 0 switches it off.
  double transport_velocity_pb = 0.0;

  // Elastic (Total-Lagrangian SPH, paper section 3.2)
  double youngs_modulus = 0.0;
  double poisson_ratio = 0.0;
  double hourglass = 10.0;   // Ganzenmueller 2015 hourglass coefficient
  bool neo_hookean = false;  // false: Saint Venant-Kirchhoff (paper eq. 16); true: compressible neo-Hookean
  double solid_art_viscosity = 1.0;  // artificial viscosity alpha for solids
  // Gradient correction: true, second order (quadratic moving-least-squares fit); false, first order
  // (Bonet & Lok 1999). See Solids::Solids().
  bool second_order_gradient = true;

  // Shell (one layer on the mid-surface, sim/solid/shell.hpp): density, youngs_modulus, poisson_ratio and
  // neo_hookean as above (plane stress), hourglass its own default (see the loader).
  double thickness = 0.0;        // [m]
  double shell_damping = 0.0;    // mass-proportional damping of velocity and spin [1/s]
  double shell_viscosity = 0.0;  // Kelvin-Voigt dynamic viscosity of the in-plane strain rate [Pa s]
  // model "lee_sacks" (incompressible, as neo_hookean, which it extends): the exponential terms
  // c1/2 (delta (exp(c2 (I1 - 3)^2) - 1) + (1 - delta) (exp(c3 (I4 - 1)^2) - 1)) of the Lee-Sacks form
  // (sim/solid/shell_material.hpp), I4 the squared stretch along the fibre direction; c1 = 0: none.
  double lee_sacks_c1 = 0.0;     // [Pa]
  double lee_sacks_c2 = 0.0;     // [-]
  double lee_sacks_c3 = 0.0;     // [-]
  double lee_sacks_delta = 1.0;  // [-] 1: isotropic (no fibre term)
};

enum class ShapeKind {
  Box,
  Sphere,
  Cylinder,
  Container,
  Tube,
  AorticRoot,
  Mesh,
  Rectangle,
  Disc,
  CylindricalPanel
};

// Graft shapes of the aortic root's graft mode (AorticRootParams::graft_shape; Unset: not given).
enum class AorticGraftShape { Unset, Straight, NeoSinus };

// Parametric aortic root and valve (sim/geometry/aortic_root.hpp; docs/scenes.md). Lengths in metres, angles
// in degrees. The root's axis is +y through `base` (the centre of the annulus disc); blood flows towards +y.
// Defaults: Labrosse et al. 2006, J. Biomech. 39:2665 (annulus, commissures, leaflet free edge and height);
// sinus radius 1.4 x annulus radius (see sim/geometry/aortic_root.hpp for the source).
struct AorticRootParams {
  Vec3 base = Vec3::Zero();
  double annulus_radius = 0.013;      // basal ring: lumen radius at the annulus plane and of the LVOT below
  double commissure_radius = 0.012;   // lumen radius at the commissures (and at the sinotubular junction)
  double commissure_height = 0.0168;  // above the annulus plane
  double sinus_radius = 0.0182;       // largest lumen radius, mid-sinus
  double stj_height = 0.0;            // sinotubular junction above the annulus; 0: commissure_height
  double aorta_radius = 0.0;          // ascending aorta; 0: commissure_radius
  double lvot_length = 0.012;         // left-ventricular outflow tube below the annulus plane
  double aorta_length = 0.03;         // ascending aorta above the sinotubular junction
  double leaflet_free_edge = 0.030;   // commissure -> centre -> next commissure
  double leaflet_height = 0.017;      // annulus nadir -> centre, along the leaflet's mid-line
  int leaflet_layers = 3;             // particle layers through the leaflet thickness (thickness = layers dx)
  int wall_layers = 3;                // fixed particle layers outside the lumen surface
  std::array<double, 3> commissure_angles = {0.0, 120.0, 240.0};  // about +y (right hand), 0 = +x
  bool sinuses = true;                                            // false: no sinus bulges (a graft)
  // Closed leaflet shape: false, Labrosse's (free edges straight to the centre, a sagging belly, a cos^2
  // attachment crown); true, the mirror image of the open leaflet (the plain cone's surface above a planar
  // attachment) across the attachment's plane (Thubrikar 1990), which opens by bending alone.
  bool mirror_leaflets = false;
  // Mirror leaflets: the open leaflet's lines leave the attachment leaning this much outward (into the sinus)
  // from the cone's [degrees]; 0: the cone itself.
  double mirror_tilt = 0.0;
  // Not a scene key: true when the leaflets are shells (a leaflet body with a shell material, issue 16), set
  // by the scene loader on every part of the root, so the leaflets sample one layer on their mid-surface and
  // the blood keeps its gap from that layer (sim/geometry/aortic_root.hpp).
  bool shell_leaflets = false;
  // Commissure posts (shell leaflets; sim/geometry/aortic_root.hpp): within this distance [m] of each
  // commissure's top point the two leaflets that meet there are clamped and the space between them (below
  // both sheets) is wall. Negative: the default, commissure_post_default() for shell mirror leaflets, else 0.
  double commissure_post = -1.0;
  double commissure_post_length() const {
    if (commissure_post >= 0.0) return commissure_post;
    return shell_leaflets && mirror_leaflets ? commissure_post_default : 0.0;
  }
  static constexpr double commissure_post_default = 0.005;
  // The lunula (shell leaflets; sim/geometry/aortic_root.hpp): each leaflet's free margin stands this high
  // [m] above its closure line at the centre, as a band on the leaflet's side of its coaptation planes,
  // tapering to nothing at the commissures. 0: none (the free edge is the closure line).
  double lunula_height = 0.0;
  // The radius [m] over which the lunula tapers, h (1 - (r / lunula_radius)^2) at radius r along the free
  // edge, none beyond; 0: commissure_radius (the whole free edge).
  double lunula_radius = 0.0;
  // The lunula's material (a shell material's name; empty: the leaflet's): a real lunula is thinner than the
  // belly, and a lunula as stiff as the leaflet stands on its free edge like a rib (docs/scenes.md,
  // "Lunula").
  std::string lunula_material;
  // Surgical geometry (issue 19 item 1; docs/scenes.md, sim/geometry/aortic_root.hpp surgical_root). Graft
  // mode: graft_diameter > 0 makes the root a graft of that inner diameter (commissure and sinotubular-
  // junction radius = graft_diameter / 2; the annulus keeps annulus_radius), straight or with neo-sinuses
  // bulging neo_sinus_bulge out of it; 0: the native root.
  double graft_diameter = 0.0;
  AorticGraftShape graft_shape = AorticGraftShape::Unset;
  double neo_sinus_bulge = 0.0;
  // Native root: lumen diameter at the sinotubular junction; 0: 2 commissure_radius.
  double stj_diameter = 0.0;
  // Cusps "fixed": the patient's cusps (free edge leaflet_free_edge, geometric height leaflet_height) kept
  // whatever the root; Labrosse leaflets always are, mirror leaflets get the mirror_tilt that keeps the free
  // edge. "root" (false): mirror leaflets follow the root.
  bool fixed_cusps = false;

  double stj() const { return stj_height > 0.0 ? stj_height : commissure_height; }
  double stj_radius() const { return stj_diameter > 0.0 ? 0.5 * stj_diameter : commissure_radius; }
  double aorta() const { return aorta_radius > 0.0 ? aorta_radius : stj_radius(); }
  // Every member (sample_aortic_root shares one root between the bodies of equal parameters).
  bool operator==(const AorticRootParams&) const = default;
};

enum class AorticPart { Wall, Blood, Leaflet };

struct Shape {
  ShapeKind kind = ShapeKind::Box;
  Box box;                        // box, container (inner box)
  Vec3 center = Vec3::Zero();     // sphere
  double radius = 0.0;            // sphere, cylinder, tube (inner radius)
  Vec3 base = Vec3::Zero();       // cylinder, tube: centre of the base disc
  Vec3 axis = Vec3::UnitY();      // cylinder, tube: unit axis
  double length = 0.0;            // cylinder, tube
  int layers = 3;                 // container, tube: particle layers outside the surface
  std::vector<std::string> open;  // container: faces left out, "+x","-x","+y","-y","+z","-z"; tube: "+", "-"
                                  // ends capped unless open (tube ends are open by default)
  std::string mesh_file;          // mesh
  AorticRootParams aortic;        // aortic_root: the root's geometry
  AorticPart aortic_part = AorticPart::Wall;  // aortic_root: which part this body is
  int aortic_index = 0;                       // aortic_root leaflets: 0, 1, 2
  // Shell shapes (one layer of particles; docs/scenes.md): rectangle (center, size, normal, u_axis), disc
  // (center, radius, normal, rim), cylindrical_panel (center, axis, radius, length, angle, normal).
  Vec3 normal = Vec3::UnitZ();
  std::optional<Vec3> u_axis;           // rectangle: in-plane direction of size[0]
  std::array<double, 2> size = {0, 0};  // rectangle
  double angle = 0.0;                   // cylindrical_panel: whole opening angle [degrees]
  int rim = 0;                          // disc: outermost ring 0 free, 1 fixed, 2 pinned
};

// A value that may vary in time: one constant, or a table of (t, value) pairs with strictly increasing times,
// interpolated linearly and held at its first / last value outside the table.
struct TimeSeries {
  std::vector<double> t;      // empty for a constant
  std::vector<double> value;  // one entry for a constant
  double at(double time) const {
    if (t.empty()) return value.empty() ? 0.0 : value[0];
    if (time <= t.front()) return value.front();
    if (time >= t.back()) return value.back();
    std::size_t k = 1;
    while (t[k] < time) ++k;
    const double w = (time - t[k - 1]) / (t[k] - t[k - 1]);
    return value[k - 1] + w * (value[k] - value[k - 1]);
  }
};

enum class RenderMode { Particles, Surface, Hidden };

// An initial flow field of a fluid body (docs/scenes.md, bodies[].initial_flow), added to its uniform
// velocity. Taylor-Green vortex (Taylor & Green 1937), the 2-D array of counter-rotating vortices in the x-y
// plane with k = 2 pi / wavelength and x, y measured from domain.min: u = U sin kx cos ky, v = -U cos kx sin
// ky, with its pressure p = p_b + rho0 U^2 / 4 (cos 2kx + cos 2ky) (the density from the equation of state).
struct InitialFlow {
  double speed = 0.0;       // U [m/s]
  double wavelength = 1.0;  // [m]
};

struct Body {
  std::string name;
  int material = 0;  // index into Scene::materials
  Shape shape;
  Vec3 translate = Vec3::Zero();
  Vec3 rotate_axis = Vec3::UnitY();
  double rotate_degrees = 0.0;
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
  std::optional<Vec3> color;  // rgb in 0..1
  RenderMode render = RenderMode::Particles;
  std::optional<Box> fixed;                 // elastic bodies: particles inside are clamped
  std::optional<InitialFlow> taylor_green;  // fluid bodies: initial_flow.taylor_green
  // Fluid bodies, `jitter` (issue 20): each particle moved from its lattice site by up to jitter * spacing
  // along each axis (0: off, the exact lattice), a fixed pseudo-random offset (World's constructor), so that
  // the lattice's mirror symmetry does not outlive the start (docs/model.md, transport velocity).
  double jitter = 0.0;
  // Shell bodies: supports (each a list of boxes): fixed holds position and director, pinned the position.
  std::vector<Box> shell_fixed, shell_pinned;
  // Shell bodies: the fibre direction of a Lee-Sacks material with fibres, projected on each particle's
  // tangent plane (the aortic leaflets take the circumferential direction unless this is given).
  std::optional<Vec3> fibre_direction;
  std::optional<TimeSeries> pressure_load;  // shell bodies: pressure along the normal [Pa]
  // Wall, rigid and elastic bodies, `"slip": "free_slip"` (issue 20): no viscous shear between the fluid and
  // the body's particles (fluid/fluid_wcsph.cpp); default no slip (Adami et al. 2012, eq. 22).
  bool free_slip = false;
};

struct Contact {
  double stiffness = 0.0;  // k, paper eq. (23) [N/m]
  double damping = 0.0;    // eta, eq. (24) [N s/m]
  double shear = 0.0;      // eq. (25) [N s/m]
  double friction = 0.5;   // Coulomb bound on the shear force
  // Shell contact (sim/solid/shell_contact.hpp): barrier modulus K [Pa] (0: off), margin added to the
  // half thicknesses [m] (< 0: half the mean thickness of the pair's shells), damping ratio.
  double shell_stiffness = 0.0;
  double shell_margin = -1.0;
  double shell_damping = 0.5;
  // Fluid against a sheet's thickness (ShellCoupling::barrier_begin): the barrier's modulus in units of the
  // fluid's rho0 c0^2 (0: off; on by default since stop 34).
  double shell_fluid_barrier = 1.0;
};

enum class ProbeType {
  Extent,
  Pressure,
  BodyState,
  Point,
  Energy,
  Momentum,
  FlowRate,
  OrificeArea,
  OpenBoundary,
  Stress,
  Gap,
  MaxSpeed,      // largest fluid speed in a region (the jet through a valve)
  Coaptation,    // leaflet coaptation heights and lengths, effective height (docs/valve-metrics.md)
  Displacement,  // displacement of the body particle nearest a point at t = 0
  GapArea,       // the orifice's open area split into central and commissural parts (docs/valve-metrics.md)
  WallDistance,  // how close the leaflets come to the wall (a leaflet striking a straight graft)
};

struct Probe {
  std::string name;
  ProbeType type = ProbeType::Extent;
  std::vector<int> bodies;  // extent, orifice_area, stress, gap: indices into Scene::bodies
  int body = -1;            // body, point, orifice_area
  int axis = 0;             // extent: 0,1,2 = x,y,z
  bool stat_max = true;     // extent: max or min
  // extent, `"stat": "extent"`: the largest coordinate of the continuous fluid (the largest cluster of
  // particles linked closer than `link`, sim/io/probes.cpp) instead of the largest of any particle.
  bool stat_extent = false;
  double link = 0.0;  // extent: link distance [m]; 0: the kernel support 2h
  std::optional<Box> region;
  Vec3 point = Vec3::Zero();      // pressure, flow_rate, orifice_area
  Vec3 normal = Vec3::UnitY();    // flow_rate, orifice_area
  Vec3 reference = Vec3::Zero();  // point
  double radius = 0.0;            // flow_rate, orifice_area
  double distance = 0.0;          // coaptation: contact distance [m]
  double central_radius = 0.0;    // coaptation, gap_area: radius about the axis counted as the centre [m]
  std::vector<Vec3> commissures;  // gap_area: the commissures (only their direction about the axis counts)
  bool per_body = false;          // stress: per body max, p95 and the peak's place (docs/valve-metrics.md)
  bool smoothed = false;          // max_speed: the speed of the kernel-averaged velocity (docs/scenes.md)
  std::vector<int> walls;         // wall_distance: the wall bodies
  double exclude = 0.0;           // wall_distance: leaflet particles this close to a wall at t = 0 left out
  double reach = 0.0;             // wall_distance: distances are capped here [m]
};

enum class OpenBoundaryType { Inflow, Outflow };

// An inflow or outflow (docs/scenes.md, sim/boundary/open_boundary.hpp): a buffer cylinder of `layers`
// particle layers behind (inflow) or beyond (outflow) the disc of centre `point`, unit `normal` and `radius`.
struct OpenBoundarySpec {
  std::string name;
  OpenBoundaryType type = OpenBoundaryType::Inflow;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();  // inflow: into the domain; outflow: out of the domain
  double radius = 0.0;
  int layers = 4;
  int body = -1;           // inflow: the fluid body that the entering particles join
  TimeSeries velocity;     // inflow: mean velocity over the inlet [m/s]
  bool parabolic = false;  // inflow: Poiseuille profile instead of uniform
  TimeSeries pressure;     // outflow: pressure at the outlet face [Pa]
  // Inflow given `pressure` instead of `velocity` (issue 17): pressure Dirichlet, velocity Neumann; the
  // pressure at the inlet face [Pa], absolute in the fluid's terms.
  bool pressure_inlet = false;
  Waveform inlet_pressure;
  // Outflow given `windkessel` instead of `pressure` (issue 17): the outlet pressure is the RCR model's
  // (sim/physiology/windkessel.hpp), driven by the flow out.
  std::optional<WindkesselParams> windkessel;
  // `non_reflecting` (issue 17 item 3): relaxation time tau [s] of the characteristic (partially
  // non-reflecting) treatment of open_boundary.hpp; 0: off (the plain Dirichlet condition, reflecting).
  double non_reflecting_tau = 0.0;
};

struct Camera {
  std::string name;
  Vec3 eye = Vec3(0, 0, 1);
  Vec3 target = Vec3::Zero();
  Vec3 up = Vec3::UnitY();
  double fov_deg = 35.0;
  // Optional per-camera overrides of the run-wide render settings, for this camera's frames and the figures
  // drawn from it (docs/scenes.md). Unset: the run-wide value (RenderSettings::*_of below).
  std::optional<std::string> color_by;
  std::optional<std::string> colormap;
  std::optional<std::pair<double, double>> range;
  std::vector<int> hide;  // bodies this camera does not draw (indices into Scene::bodies)
  bool clip = true;       // false: render.clip does not apply to this camera
};

struct Figure {
  std::string name;
  std::string camera;
  std::vector<double> times;
  int columns = 3;
};

struct Clip {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  std::vector<int> bodies;  // bodies cut by the plane (the half on the +normal side is removed)
};

struct RenderSettings {
  int width = 1280;
  int height = 720;
  Vec3 background = Vec3(1, 1, 1);
  std::string color_by = "material";  // material, speed, pressure, displacement, stress
  std::string colormap = "viridis";
  std::optional<std::pair<double, double>> range;
  std::vector<Camera> cameras;
  std::optional<Clip> clip;
  std::vector<Figure> figures;

  // What a camera draws with: its own setting where it has one, else the run-wide one. A camera inherits
  // `range` only when it colours by the run's field (a range in m/s means nothing for a stress in Pa); else
  // its range is chosen from the particles it draws.
  const std::string& color_by_of(const Camera& c) const { return c.color_by ? *c.color_by : color_by; }
  const std::string& colormap_of(const Camera& c) const { return c.colormap ? *c.colormap : colormap; }
  std::optional<std::pair<double, double>> range_of(const Camera& c) const {
    if (c.range) return c.range;
    return color_by_of(c) == color_by ? range : std::nullopt;
  }
  const Clip* clip_of(const Camera& c) const { return c.clip && clip ? &*clip : nullptr; }
  // The fields the cameras colour by, each once, in camera order ("material" is not a field).
  std::vector<std::string> fields() const {
    std::vector<std::string> out;
    for (const Camera& c : cameras) {
      const std::string& f = color_by_of(c);
      if (f != "material" && std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
    }
    return out;
  }
};

// The cardiac cycle of a run (docs/scenes.md "cycle", docs/valve-metrics.md): the period, and the probe
// columns the per-cycle valve metrics read (empty: not measured).
struct CycleSpec {
  double period = 0.8;  // [s]
  int cycles = 0;       // 0: as many as time.end holds
  double start = 0.0;   // cycle k is [start + k period, start + (k+1) period)
  std::string lv_pressure, aortic_pressure, valve_flow, orifice_area, jet_speed, lvot_flow;  // columns
  double lvot_area = 0.0;       // [m^2]; 0: from the lvot_flow (or valve_flow) probe's disc
  std::string stress;           // a stress probe's name
  std::string coaptation;       // a coaptation probe's name
  std::string gap_area;         // a gap_area probe's name
  std::string wall_distance;    // a wall_distance probe's name
  double hold_level = 9332.57;  // [Pa] diastolic pressure difference counted as held (70 mmHg)
  double density = 1060.0;      // [kg/m^3] fluid density for the Gorlin EOA
  // [Pa] the fluid pressure that reads 0 mmHg in the LV and aortic pressure metrics (default: the first
  // fluid's background_pressure, the pressure of blood at rest)
  double pressure_zero = 0.0;
};

struct Scene {
  std::string name;
  Box domain;
  std::array<bool, 3>
      periodic{};  // periodic axes x, y, z (sim/core/periodic.hpp): the domain's length is the period
  double max_leave_fraction = 0.0;
  // The pressure the momentum equation measures from (docs/model.md, "Pressure gauge"): with
  // `open_boundaries` (the default) the lowest pressure that an open boundary prescribes, less the fluid's
  // background pressure (never below 0); with `none`, 0.
  bool pressure_gauge_open = true;
  double spacing = 0.01;
  double smoothing_ratio = 1.3;  // h = smoothing_ratio * spacing
  // The Verlet lists' skin as a fraction of the kernel support: lists hold pairs within support (1 + skin)
  // and are rebuilt when a particle has moved skin / 2 (World::update_neighbors).
  double skin = 0.1;
  double t_end = 1.0;
  double output_interval = 0.01;
  // Rows of probes.csv and diagnostics.csv at k * probe_interval; output_interval is a whole multiple of it
  // (frames and VTK files at every output, a row at each). The loader sets it (default output_interval).
  double probe_interval = 0.01;
  double cfl = 0.25;
  double max_dt = 1e-3;
  double max_speed = 0.0;          // instability limit [m/s]; 0 = derived from the sound speed
  double max_density_error = 0.5;  // instability limit on max |rho / rho0 - 1| of fluid particles; 0 = off
  double fixed_dt = 0.0;           // > 0: every step has this length, stable or not (for debugging and tests)
  Vec3 gravity = Vec3(0, -9.81, 0);
  std::vector<Material> materials;
  Contact contact;
  std::vector<Body> bodies;
  std::vector<OpenBoundarySpec> open_boundaries;
  std::vector<Probe> probes;
  std::optional<CycleSpec> cycle;
  RenderSettings render;
};

}  // namespace aortasph
