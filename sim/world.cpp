#include "world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "boundary/boundary.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "fluid/transport_velocity.hpp"
#include "geometry/shapes.hpp"

namespace aortasph {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string fmt_vec(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

std::array<float, 3> default_color(MaterialType t) {
  switch (t) {
    case MaterialType::Fluid:
      return {0.22f, 0.47f, 0.85f};
    case MaterialType::Wall:
      return {0.62f, 0.62f, 0.62f};
    case MaterialType::Rigid:
      return {0.90f, 0.50f, 0.15f};
    case MaterialType::Elastic:
      return {0.30f, 0.70f, 0.35f};
    case MaterialType::Shell:
      return {0.75f, 0.35f, 0.55f};
  }
  return {0.5f, 0.5f, 0.5f};
}

Kind kind_of(MaterialType t) {
  switch (t) {
    case MaterialType::Fluid:
      return Kind::Fluid;
    case MaterialType::Wall:
      return Kind::Wall;
    case MaterialType::Rigid:
      return Kind::Rigid;
    case MaterialType::Elastic:
      return Kind::Elastic;
    case MaterialType::Shell:
      return Kind::Shell;
  }
  return Kind::Wall;
}

}  // namespace

// Body::jitter: each point of body b moved by up to `amplitude` along each axis, by an offset that depends
// only on (b, point index, axis) (SplitMix64, Steele, Lea & Flood 2014, as a counter-based generator): the
// same on every machine and for any thread count. Out through a periodic face, in through the other.
void World::jitter_points(std::vector<Vec3>& points, std::size_t b, double amplitude) const {
  auto uniform = [](uint64_t n) {  // in [-1, 1)
    uint64_t z = n + 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
  };
  for (std::size_t k = 0; k < points.size(); ++k) {
    const uint64_t n = (static_cast<uint64_t>(b) << 40) + 3 * static_cast<uint64_t>(k);
    points[k] += amplitude * Vec3(uniform(n), uniform(n + 1), uniform(n + 2));
    if (ctx_.periodic.any) ctx_.periodic.wrap(points[k]);
  }
}

World::World(const Scene& scene)
    : scene_(scene),
      kernel_(scene.smoothing_ratio * scene.spacing),
      gravity_(scene.gravity),
      ctx_{kernel_, fluid_, gravity_, {}, {}, Periodic(scene.domain, scene.periodic)} {
  const double dx = scene_.spacing;
  const double volume = dx * dx * dx;
  ctx_.inv_w_dx = 1.0 / kernel_.W(dx);
  ctx_.hydrostatic_gravity = ctx_.periodic.across(gravity_);
  std::vector<uint8_t> clamped;       // per particle: elastic and held in place
  std::vector<ShellSeed> shell_seed;  // per particle: shells' normal, area and support

  // Read-only per-material constants.
  fluid_.resize(scene_.materials.size());
  bool have_fluid = false;
  for (std::size_t m = 0; m < scene_.materials.size(); ++m) {
    const Material& mat = scene_.materials[m];
    if (mat.type != MaterialType::Fluid) continue;
    fluid_[m] = FluidParams(mat);
    if (!have_fluid) wall_ref_ = fluid_[m];
    have_fluid = true;
    max_c0_ = std::max(max_c0_, mat.sound_speed);
    max_nu_ = std::max(max_nu_, mat.viscosity);
    shifting_ = shifting_ || mat.shifting > 0.0;
    transport_ = transport_ || mat.transport_velocity_pb > 0.0;
    mask_density_on_ = mask_density_on_ || fluid_[m].mask_density;
  }
  if (!have_fluid) wall_ref_ = FluidParams(Material{});

  // Sample the bodies.
  for (std::size_t b = 0; b < scene_.bodies.size(); ++b) {
    const Body& body = scene_.bodies[b];
    const Material& mat = scene_.materials.at(body.material);
    const std::string where = "bodies[" + std::to_string(b) + "] '" + body.name + "'";
    ShapeSample sample = sample_body(body, dx);
    if (sample.points.empty())
      throw SetupError(where + ": the shape holds no particle at spacing " + std::to_string(dx));
    if (body.jitter > 0.0 && mat.type == MaterialType::Fluid)
      jitter_points(sample.points, b, body.jitter * dx);
    if (scene_.bodies.size() > std::numeric_limits<uint16_t>::max())
      throw SetupError("bodies: too many bodies");

    BodyInfo info;
    info.name = body.name;
    info.type = mat.type;
    info.material = body.material;
    info.count = sample.points.size();
    info.mesh = std::move(sample.mesh);

    Vec3 centroid = Vec3::Zero();
    for (const Vec3& p : sample.points) centroid += p;
    centroid /= static_cast<double>(sample.points.size());

    // Boundary particles (walls, bodies) enter the fluid's sums with the fluid's mass per particle, rho0 dx^3
    // (Adami et al. 2012 use volumes); a body's own mass lives in its RigidBody.
    const double rho0 = mat.type == MaterialType::Fluid ? mat.density : wall_ref_.rho0;
    // An aortic shell leaflet's lunula may have its own material (the scene loader checked it is a shell).
    uint16_t lunula_material = static_cast<uint16_t>(body.material);
    if (!sample.lunula.empty() && !body.shape.aortic.lunula_material.empty())
      for (std::size_t m = 0; m < scene_.materials.size(); ++m)
        if (scene_.materials[m].name == body.shape.aortic.lunula_material)
          lunula_material = static_cast<uint16_t>(m);
    const std::size_t first = P_.size();
    P_.resize(first + sample.points.size());
    for (std::size_t k = 0; k < sample.points.size(); ++k) {
      const std::size_t i = first + k;
      P_.x[i] = sample.points[k];
      P_.x0[i] = sample.points[k];
      P_.kind[i] = kind_of(mat.type);
      P_.body[i] = static_cast<uint16_t>(b);
      P_.material[i] =
          !sample.lunula.empty() && sample.lunula[k] ? lunula_material : static_cast<uint16_t>(body.material);
      P_.id[i] = static_cast<uint32_t>(i);
      P_.m[i] = rho0 * volume;
      P_.rho[i] = rho0;
      if (mat.type != MaterialType::Wall)
        P_.v[i] = body.velocity + body.angular_velocity.cross(sample.points[k] - centroid);
    }
    if (body.taylor_green && mat.type == MaterialType::Fluid) {
      const InitialFlow& tg = *body.taylor_green;
      const FluidParams fp(mat);
      const double k = 2.0 * M_PI / tg.wavelength;
      for (std::size_t i = first; i < P_.size(); ++i) {
        const double x = k * (P_.x[i].x() - scene_.domain.min.x()),
                     y = k * (P_.x[i].y() - scene_.domain.min.y());
        P_.v[i] += tg.speed * Vec3(std::sin(x) * std::cos(y), -std::cos(x) * std::sin(y), 0.0);
        const double p =
            fp.p_background + 0.25 * mat.density * tg.speed * tg.speed * (std::cos(2 * x) + std::cos(2 * y));
        P_.rho[i] = fp.density(p);
      }
    }

    // Elastic particles held at their reference position: the scene's fixed region and what the shape
    // clamps itself (a leaflet's attachment to the wall).
    if (mat.type == MaterialType::Elastic) {
      clamped.resize(P_.size(), 0);
      std::size_t held = 0;
      for (std::size_t k = 0; k < sample.points.size(); ++k) {
        const bool c = (body.fixed && body.fixed->contains(sample.points[k])) ||
                       (!sample.clamped.empty() && sample.clamped[k]);
        clamped[first + k] = c;
        held += c;
      }
      if (body.fixed && held == 0)
        throw SetupError(where + ".fixed: the region holds no particle of the body");
    }
    if (mat.type == MaterialType::Shell) add_shell_seeds(body, where, sample, first, shell_seed);

    // Fluid under gravity starts in hydrostatic balance: p = rho0 |g| depth below the body's top, and the
    // density that the equation of state gives for it. Without this the column would first oscillate.
    // Gravity along a periodic axis drives a flow and has no hydrostatic balance (Periodic::across): until
    // stop 51 the periodic pipe of the tests started with a 3.4 % density ramp along its axis, and a jump
    // of 40 Pa (rho0 g over 15 mm) where its ends meet.
    const double g = ctx_.hydrostatic_gravity.norm();
    if (mat.type == MaterialType::Fluid && g > 0.0) {
      const Vec3 up = -ctx_.hydrostatic_gravity / g;
      double top = std::numeric_limits<double>::lowest();
      for (const Vec3& p : sample.points) top = std::max(top, up.dot(p));
      top += 0.5 * dx;
      for (std::size_t k = 0; k < sample.points.size(); ++k) {
        const std::size_t i = first + k;
        const double p = mat.density * g * (top - up.dot(P_.x[i]));
        P_.rho[i] = fluid_[body.material].density(p);
        P_.p[i] = fluid_[body.material].pressure(P_.rho[i]);
      }
    }
    if (mat.type == MaterialType::Rigid) {
      info.rigid = static_cast<int>(rigid_.size());
      rigid_.push_back(make_rigid_body(static_cast<int>(b), sample.points, mat.density * volume, dx,
                                       body.velocity, body.angular_velocity));
      // A rigid body answers a contact with its whole mass M, and up to about n^(2/3) of its n particles (one
      // face) can touch at once: the stiffest mode has mass M / n^(2/3) on one spring.
      const double n = static_cast<double>(sample.points.size());
      min_contact_mass_ = std::min(min_contact_mass_, rigid_.back().mass / std::cbrt(n * n));
    }
    bodies_.push_back(std::move(info));
  }
  // Free-slip boundary bodies (Body::free_slip): left out of the fluid's viscous term.
  for (std::size_t b = 0; b < scene_.bodies.size(); ++b)
    if (scene_.bodies[b].free_slip) {
      ctx_.free_slip.resize(scene_.bodies.size(), 0);
      ctx_.free_slip[b] = 1;
    }
  contact_ = ContactParams{scene_.contact.stiffness,
                           scene_.contact.damping,
                           scene_.contact.shear,
                           scene_.contact.friction,
                           dx,
                           false};
  if (P_.size() > std::numeric_limits<uint32_t>::max() / 4) throw SetupError("too many particles");

  // Bodies may touch but not overlap: particles of two bodies closer than half a spacing are an error (less
  // a rounding margin: a sheet on a fluid's lattice plane lies exactly half a spacing from its particles).
  nb_.set_periodic(ctx_.periodic);
  nb_.build(P_.x, 0.5 * dx * (1.0 - 1e-9));
  for (std::size_t i = 0; i < P_.size(); ++i)
    for (uint32_t k = nb_.begin(i); k < nb_.end(i); ++k) {
      const uint32_t j = nb_.index()[k];
      if (P_.body[j] != P_.body[i])
        throw SetupError("bodies '" + scene_.bodies[P_.body[i]].name + "' and '" +
                         scene_.bodies[P_.body[j]].name + "' overlap near " + fmt_vec(P_.x[i]) +
                         ": particles closer than half a spacing");
    }
  nb_.release();  // its grid of cells of a quarter spacing is larger than the lists' grid

  // Inflow buffer particles join the bodies; fluid already beyond an outlet disc becomes outflow buffer.
  if (!scene_.open_boundaries.empty()) open_.setup(scene_, fluid_, P_);

  if (shifting_) P_.shift.assign(P_.size(), Vec3::Zero());  // (Particles::shift; none shifted yet)
  for (std::size_t i = 0; i < P_.size(); ++i)
    if (P_.kind[i] != Kind::Wall) ++moving_at_start_;
  speed_limit_ = scene_.max_speed > 0.0 ? scene_.max_speed : (max_c0_ > 0.0 ? 2.0 * max_c0_ : 1e3);
  max_accel_ = gravity_.norm();
  for (const Vec3& v : P_.v) max_speed_ = std::max(max_speed_, v.norm());

  // Elastic solids: reference configuration, neighbours and corrections, once. `clamped` was filled by
  // sampling index, which is the particle id; the open boundaries may have removed fluid since, so it is read
  // by id.
  {
    std::vector<uint8_t> by_index(P_.size(), 0);
    for (std::size_t i = 0; i < P_.size(); ++i)
      if (P_.id[i] < clamped.size()) by_index[i] = clamped[P_.id[i]];
    clamped = std::move(by_index);
  }
  solids_ = Solids(P_, scene_.materials, kernel_, dx, clamped);
  if (!shell_seed.empty()) {
    std::vector<ShellSeed> by_index(P_.size());
    for (std::size_t i = 0; i < P_.size(); ++i)
      if (P_.id[i] < shell_seed.size()) by_index[i] = shell_seed[P_.id[i]];
    shells_ = Shells(P_, scene_.materials, kernel_, by_index, ctx_.periodic);
    shells_.update(P_);
    {  // the sheets drawn and written for the shell bodies: edges up to 1.75 dx (solid/shell_mesh.hpp; the
       // curved sampling of the aortic leaflets has cells with both diagonals 1.52 dx, holes at 1.5 dx)
      std::vector<uint16_t> body_of(shells_.size());
      for (std::size_t s = 0; s < shells_.size(); ++s) body_of[s] = P_.body[shells_.at(s)];
      sheets_ = ShellSheets(shells_, body_of, 1.75 * dx);
    }
    shell_contact_ = ShellContact(
        {scene_.contact.shell_stiffness, scene_.contact.shell_margin, scene_.contact.shell_damping, dx},
        kernel_.support);
    contact_.skip_shells = shell_contact_.active();  // the shells' own contact replaces eqs. 23-25 there
    for (const Material& m : scene_.materials)
      if (m.type == MaterialType::Shell) min_shell_thickness_ = std::min(min_shell_thickness_, m.thickness);
    if (have_fluid) {  // fluid on either side of a sheet (sim/boundary/shell_coupling.hpp)
      coupling_ = ShellCoupling(P_, shells_, sheets_.triangles(), dx, kernel_.support, wall_ref_.rho0);
      ctx_.shell_wall = &coupling_.wall();
      // The fluid's barrier modulus per material (ShellCoupling::barrier): the scene's factor of rho0 c0^2.
      if (scene_.contact.shell_fluid_barrier > 0.0)
        for (const FluidParams& f : fluid_)
          barrier_modulus_.push_back(scene_.contact.shell_fluid_barrier * f.rho0 * f.c0 * f.c0);
    }
  }
  if (!solids_.empty() && contact_.k > 0.0)
    min_contact_mass_ = std::min(min_contact_mass_, solids_.min_mass());
  // Shell contact in the shells' sub-steps (step_shells) where a fluid sets the step and no elastic body
  // takes part in the contact. An elastic body is not sub-stepped: its contact with a sheet stays held over
  // the step, as before stop 52. Without a fluid nothing but max_dt would bound the step (the shells' own
  // bounds are the sub-steps'), and a sheet could leave its neighbour lists within one step: there too the
  // contact is held and bounds the step (the [shell_contact] tests).
  contact_in_substeps_ = shell_contact_.active() && solids_.empty() && max_c0_ > 0.0;

  // Spatial sort once, so neighbours sit close in memory from the first step.
  skin_ = scene.skin * kernel_.support;
  open_.set_list_reach(kernel_.support + skin_);
  nb_.bin(P_.x, kernel_.support);  // the cells alone: spatial_order() needs no lists
  permute(nb_.spatial_order());
  build_lists();
  fluid_pressure(P_, ctx_);
  boundary_from_fluid(P_, nb_, ctx_, wall_ref_);
}

std::size_t World::count(Kind k) const {
  return static_cast<std::size_t>(std::count(P_.kind.begin(), P_.kind.end(), k));
}

double World::stable_dt() const {
  if (scene_.fixed_dt > 0.0) return scene_.fixed_dt;
  const double h = kernel_.h;
  double dt = scene_.max_dt;
  // Acoustic CFL (Monaghan 1992): information crosses h in no less than h / (c0 + |v|max). |v|max includes
  // the shells' own sub-step speeds, so that a sheet also moves less than cfl h (a third of a spacing) per
  // fluid step: the coupling (side labels, the guard, the imaginary particles of sim/boundary/shell_coupling)
  // is rebuilt once per step and needs the sheet to move a fraction of a spacing in between.
  if (max_c0_ > 0.0) dt = std::min(dt, scene_.cfl * h / (max_c0_ + std::max(max_speed_, sub_.max_speed)));
  // Elastic solids: the same condition with the P-wave speed sqrt((lambda + 2 mu) / rho), the fastest signal
  // of the solid.
  if (!solids_.empty()) dt = std::min(dt, scene_.cfl * h / (solids_.max_wave_speed() + max_speed_));
  // Shells do not bound the step: they take their own sub-steps within it (step_shells).
  // Shell contact held over the shells' sub-steps (an elastic body in the scene: contact_in_substeps_
  // false): the contact spring and damper of the particles near contact (ShellContact::stable_dt), from the
  // lists (stale right after particles were created or removed: then the bound waits a step), and no sheet
  // may move more than a quarter of the thinnest sheet's thickness (under the contact distance) in one
  // step, or it could pass through a partner between two evaluations. With the contact in the sub-steps
  // these bound the sub-steps instead (shell_stable_dt).
  if (shell_contact_.active() && !contact_in_substeps_ && lists_valid_)
    dt = std::min(dt, shell_contact_.stable_dt(P_, nb_, shells_, ctx_.periodic, scene_.cfl));
  if (const double v = std::max(max_speed_, sub_.max_speed);
      shell_contact_.active() && !contact_in_substeps_ && v > 0.0)
    dt = std::min(dt, 0.25 * min_shell_thickness_ / v);
  // Viscous diffusion limit (Morris, Fox & Zhu 1997, eq. 18): dt <= 0.125 h^2 / nu.
  if (max_nu_ > 0.0) dt = std::min(dt, 0.125 * h * h / max_nu_);
  // Contact spring: two particles of mass m on a spring k touch for about pi sqrt(m / 2k) (m: see the
  // constructor for bodies of many particles). With rigid bodies, cfl * 0.1 sqrt(m / k) resolves a contact in
  // about 90 steps at cfl 0.25; the damped restitution converges to first order in dt and is then within 2 %
  // of the spring-dashpot formula up to zeta = 0.5 (tests/test_rigid.cpp). Between elastic bodies only (valve
  // leaflets closing) no bounce is measured and stability is what counts: a particle pressed by up to 9
  // particles of the other body, both sides moving, is stable for dt < 2 / sqrt(18 k / m) = 0.47 sqrt(m / k),
  // and cfl sqrt(m / k) keeps under it. (The 0.1 there made a 100x stiffer leaflet contact cost 7x the
  // steps.)
  if ((!rigid_.empty() || !solids_.empty()) && contact_.k > 0.0)
    dt = std::min(dt, scene_.cfl * (rigid_.empty() ? 1.0 : 0.1) * std::sqrt(min_contact_mass_ / contact_.k));
  // Contact dampers (eqs. 24, 25), explicit: a particle of mass m on a damper eta is stable for dt < 2 m /
  // eta; cfl m / eta leaves room for the several contacts a particle may have at once.
  if ((!rigid_.empty() || !solids_.empty()) && contact_.k > 0.0 &&
      std::max(contact_.eta, contact_.shear) > 0.0)
    dt = std::min(dt, scene_.cfl * min_contact_mass_ / std::max(contact_.eta, contact_.shear));
  // Force limit (Monaghan 1992): dt <= 0.25 sqrt(h / |a|max).
  if (max_accel_ > 0.0) dt = std::min(dt, 0.25 * std::sqrt(h / max_accel_));
  return dt;
}

std::vector<uint8_t> World::fixed_mask() const {
  std::vector<uint8_t> fixed(P_.size());
  for (std::size_t i = 0; i < P_.size(); ++i) fixed[i] = P_.kind[i] == Kind::Wall;
  return fixed;
}

// Verlet lists (Verlet 1967): the lists hold every pair closer than the kernel support plus a skin, and are
// rebuilt only when some particle has moved half a skin since the last build, so no pair within the support
// can be missing. Pairs between support and support + skin cost a little in every loop (the kernel is zero
// there) and save most rebuilds. Every few rebuilds the particles are also re-sorted along a Z-order curve of
// the cells so that neighbours stay close in memory as the flow mixes them.
void World::update_neighbors() {
  const auto t0 = Clock::now();
  if (!lists_valid_) {
    build_lists();
  } else {
    // The fixed walls never move: only the others are tested (the maximum is the same).
    const double moved2 = parallel_reduce(
        skin_index_.size(), 0.0,
        [&](std::size_t k) { return ctx_.separation(P_.x[skin_index_[k]], x_at_build_[k]).squaredNorm(); },
        [](double a, double b) { return std::max(a, b); });
    if (4.0 * moved2 >= skin_ * skin_) build_lists();
  }
  profile_.neighbors += seconds_since(t0);
}

void World::build_lists() {
  const double radius = kernel_.support + skin_;
  // Buffer particles that left past a far face since the last build (OpenBoundaries::update) go now.
  if (!open_.empty())
    if (const std::vector<uint32_t> keep = open_.take_departed(P_); !keep.empty()) permute(keep);
  if (builds_ % sort_every_builds_ == sort_every_builds_ - 1) {
    // The sort needs only each particle's cell (bin(), as the constructor's first sort), not a full list
    // build whose lists the permutation would discard.
    const auto t0 = Clock::now();
    nb_.bin(P_.x, radius);
    permute(nb_.spatial_order());
    profile_.sort += seconds_since(t0);
  }
  nb_.build(P_.x, radius, fixed_mask());
  coupling_.on_build(P_, nb_);  // the rows near a shell, as built
  ++builds_;
  record_build_positions(P_.x);
  listed_ = P_.size();
  lists_valid_ = true;
}

// Particles appended by the open boundaries at a deep buffer's far face (OpenBoundaries::update): empty rows
// until the next build, nobody's neighbour, their positions watched for the skin like the others'.
void World::append_to_lists(std::size_t first) {
  nb_.append_rows(P_.size() - first);
  coupling_.on_append(P_.size());
  for (std::size_t i = first; i < P_.size(); ++i) {
    skin_index_.push_back(static_cast<uint32_t>(i));
    x_at_build_.push_back(P_.x[i]);
  }
}

// Memory (docs/performance.md): on the dam-break bench two thirds of the particles are walls, so keeping the
// positions of the moving ones only (24 + 4 B each) instead of all (24 B each) saves 4 MiB of 7.
void World::record_build_positions(const std::vector<Vec3>& x) {
  skin_index_.clear();
  for (std::size_t i = 0; i < P_.size(); ++i)
    if (P_.kind[i] != Kind::Wall) skin_index_.push_back(static_cast<uint32_t>(i));
  skin_index_.shrink_to_fit();
  x_at_build_.resize(skin_index_.size());
  x_at_build_.shrink_to_fit();
  parallel_for(skin_index_.size(), [&](std::size_t k) { x_at_build_[k] = x[skin_index_[k]]; });
}

std::vector<Vec3> World::build_positions() const {
  std::vector<Vec3> x = P_.x;
  if (skin_index_.size() == x_at_build_.size())
    for (std::size_t k = 0; k < skin_index_.size(); ++k) x[skin_index_[k]] = x_at_build_[k];
  return x;
}

// One time step, Algorithm 1: neighbours -> density -> pressure -> boundary -> forces -> integrate.
// The density is advanced before the forces are computed, so that the pressure driving v(t + dt) is that of
// rho(t + dt): with both taken from time t the acoustic modes would grow each step (the explicit Euler scheme
// is unconditionally unstable for an oscillator); in this order the pair (rho, v) is advanced by the
// symplectic Euler scheme, as (v, x) is in Algorithm 1 lines 15-16.
void World::step(double dt) {
  update_neighbors();
  FluidContext& ctx = ctx_;
  auto t0 = Clock::now();
  // Shells between fluids: pairs across a sheet masked, imaginary wall particles placed (timed as boundary).
  if (coupling_.active()) {
    coupling_.prepare(P_, shells_, nb_, ctx.periodic);
    // The densities across this step's changes of the masks (boundary/mask_density.hpp).
    if (mask_density_on_)
      mask_density_.apply(
          P_, nb_, ctx, [&](std::size_t i) { return coupling_.in_band(i); },
          [&](std::size_t i) { return fluid_[P_.material[i]].mask_density; });
    profile_.boundary += seconds_since(t0);
    t0 = Clock::now();
  }
  // The pressure the momentum equation measures from (docs/model.md, "Pressure gauge"), from the pressures
  // the open boundaries imposed at the end of the last step.
  ctx.gauge = scene_.pressure_gauge_open && !open_.empty() ? open_.pressure_gauge() : 0.0;
  fluid_density_summation(P_, nb_, ctx);  // eq. (11), where a material asks for it
  fluid_pair_terms(P_, ctx);
  // eq. (12) + diffusion, elsewhere; with the last step's shifts where a material counts them in its density
  // (fluid/shifting.hpp)
  ctx.shift_rate = shifting_ ? 1.0 / dt : 0.0;
  fluid_density_rate(P_, nb_, ctx);
  parallel_for(P_.size(), [&](std::size_t i) {
    if (P_.kind[i] == Kind::Fluid && !fluid_[P_.material[i]].summation) P_.rho[i] += dt * P_.drho[i];
  });
  fluid_pressure(P_, ctx);  // eq. (13)
  profile_.density += seconds_since(t0);

  t0 = Clock::now();
  boundary_from_fluid(P_, nb_, ctx, wall_ref_);  // Adami et al. 2012
  fluid_pair_terms(P_, ctx);
  profile_.boundary += seconds_since(t0);

  t0 = Clock::now();
  // Transport velocity (Adami et al. 2013): v~ - v from the positions now, before the forces (its stress
  // term enters them).
  if (transport_) fluid_transport_velocity(P_, nb_, ctx, dt, ctx.transport_dv);
  // eqs. (9), (10), artificial viscosity, gravity; and the particle shifting (Lind et al. 2012) for this
  // step, its sums carried by the same neighbour loop (applied in integrate). Bodies move after this (rigid
  // bodies in step_rigid, shells in step_shells): the shift sees their positions at t, as the forces do.
  const ShiftRequest shift{scene_.spacing, dt, &P_.shift};
  fluid_forces(P_, nb_, ctx, shifting_ ? &shift : nullptr);
  profile_.forces += seconds_since(t0);

  // Forces on body particles from the fluid and from contact (eqs. 23-25).
  t0 = Clock::now();
  if (!rigid_.empty() || !solids_.empty() || !shells_.empty()) body_forces();
  profile_.rigid += seconds_since(t0);

  t0 = Clock::now();
  if (!solids_.empty()) step_solids();    // eqs. (14)-(18)
  if (!shells_.empty()) step_shells(dt);  // one-layer shells (sim/solid/shell.hpp)
  profile_.solid += seconds_since(t0);

  t0 = Clock::now();
  if (!rigid_.empty()) step_rigid(dt);  // eqs. (19)-(22)
  profile_.rigid += seconds_since(t0);

  t0 = Clock::now();
  integrate(dt);
  if (coupling_.active())
    coupling_.guard(P_, shells_, ctx_.periodic, dt);  // no fluid particle through a sheet
  profile_.integrate += seconds_since(t0);

  // Open boundaries (sim/boundary/open_boundary.hpp): buffers move, particles that crossed an inlet or outlet
  // disc change role, are created at inflows and removed at outflows (those never count as leaving the
  // domain). Particles created or removed where the fluid could see them invalidate the neighbour lists;
  // those at the far face of a deep buffer wait for the next build (issue 18 item 1).
  t0 = Clock::now();
  if (!open_.empty()) {
    const std::size_t before = P_.size();
    const OpenBoundaryChange change = open_.update(P_, nb_, kernel_, gravity_, time_ + dt, dt);
    if (change.rebuild) {
      lists_valid_ = false;
      solids_.reindex(P_);  // particles were appended and removed: the solid's slots follow (by particle id)
      shells_.reindex(P_);
    } else if (P_.size() > before) {
      append_to_lists(before);
    }
  }
  profile_.open_boundary += seconds_since(t0);

  t0 = Clock::now();
  check_and_remove(dt);
  profile_.integrate += seconds_since(t0);

  time_ += dt;
  last_dt_ = dt;
  ++steps_;
}

// Symplectic Euler, Algorithm 1 lines 15-16: v(t + dt) = v + dt a; x(t + dt) = x + dt v(t + dt), read as
// the leapfrog it is (v lives half a step behind x). When the step length changes (advance_to() splits each
// output interval evenly, so it changes at output times; the adaptive step drifts) the kick spans the two
// half steps around x(t), (dt_prev + dt) / 2, the variable-step leapfrog (Hairer, Lubich & Wanner 2006, sec.
// VIII.1). A kick of dt alone mistimes v by (dt_prev - dt) / 2 at every change; with a shortened step before
// each output, every 55 steps, a TL-SPH beam gained 500x its energy.
void World::integrate(double dt) {
  const double kick = kick_length(dt);
  const Periodic& per = ctx_.periodic;
  parallel_for(P_.size(), [&](std::size_t i) {
    // (Shells advanced themselves in step_shells, in sub-steps.)
    if (P_.kind[i] != Kind::Fluid && P_.kind[i] != Kind::Elastic) return;
    P_.v[i] += kick * P_.a[i];
    P_.x[i] += dt * P_.v[i];
    if (!ctx_.transport_dv.empty()) P_.x[i] += dt * ctx_.transport_dv[i];  // dr/dt = v~ (Adami et al. 2013)
    if (shifting_) P_.x[i] += P_.shift[i];
    if (per.any) per.wrap(P_.x[i]);  // out through one periodic face, in through the other
  });
  struct Extremes {
    double v2 = 0, a2 = 0;
  };
  const Extremes e = parallel_reduce(
      P_.size(), Extremes{},
      [&](std::size_t i) {
        if (P_.kind[i] == Kind::Wall) return Extremes{};
        // Shells: their acceleration bounds their sub-steps (shell_stable_dt), not the step.
        if (P_.kind[i] == Kind::Shell) return Extremes{P_.v[i].squaredNorm(), 0.0};
        return Extremes{P_.v[i].squaredNorm(), P_.a[i].squaredNorm()};
      },
      [](const Extremes& a, const Extremes& b) {
        // std::max drops a NaN on one side; check_and_remove() finds NaNs itself.
        return Extremes{std::max(a.v2, b.v2), std::max(a.a2, b.a2)};
      });
  max_speed_ = std::sqrt(e.v2);
  max_accel_ = std::max(std::sqrt(e.a2), gravity_.norm());
}

// Per body particle (rigid, elastic): the fluid's reaction (equal and opposite to what the fluid feels) and
// contact forces (eqs. 23-25), with the contacts' moments for the rigid torque sums.
void World::body_forces() {
  const std::size_t n = P_.size();
  force_.assign(n, Vec3::Zero());
  moment_.assign(n, Vec3::Zero());
  fluid_reaction(P_, nb_, ctx_, force_);
  contact_forces(P_, nb_, contact_, force_, moment_);
  // sim/solid/shell_contact.hpp; in the shells' sub-steps instead where no elastic body takes part
  if (!contact_in_substeps_) shell_contact_.add_forces(P_, nb_, shells_, ctx_.periodic, force_);
  // (The fluid's barrier against a sheet acts in the shells' sub-steps: step_shells.)
}

// Elastic particles: internal forces (eqs. 14-18 with their stabilisers) plus what body_forces() found (the
// fluid's reaction and contact), over the particle's own mass, plus gravity. Clamped particles stay where
// they are, with zero velocity and acceleration (the wall boundary reads their acceleration).
void World::step_solids() {
  solids_.update_stress(P_);
  solids_.add_forces(P_, force_);
  parallel_for(solids_.size(), [&](std::size_t s) {
    const uint32_t i = solids_.at(s);
    if (solids_.clamped(s)) {
      P_.a[i] = Vec3::Zero();
      P_.v[i] = Vec3::Zero();
      return;
    }
    P_.a[i] = force_[i] / solids_.mass(s) + gravity_;
  });
}

void World::permute(const std::vector<uint32_t>& order) {
  P_.permute(order);
  solids_.reindex(P_);
  shells_.reindex(P_);
}

// Shell bodies: seeds (normal, area, support) of the particles first .. first + n of one body, by particle
// id. Supports: the body's fixed and pinned boxes and the shape's own (a disc's rim); a box that holds no
// particle of the body is an error naming the key.
void World::add_shell_seeds(const Body& body, const std::string& where, const ShapeSample& sample,
                            std::size_t first, std::vector<ShellSeed>& seeds) const {
  seeds.resize(P_.size());
  const std::size_t n = sample.points.size();
  const Material& mat = scene_.materials.at(body.material);
  const bool fibred = mat.lee_sacks_c1 > 0.0 && mat.lee_sacks_delta < 1.0;
  if (body.fibre_direction && !fibred)
    throw SetupError(where +
                     ".fibre_direction: the body's material has no fibre term (lee_sacks with delta < 1)");
  if (fibred && !body.fibre_direction && sample.fibres.empty())
    throw SetupError(where +
                     ".fibre_direction: missing (the material's fibre term, lee_sacks with delta < 1, "
                     "needs a direction; only the aortic leaflets have their own)");
  for (std::size_t k = 0; k < n; ++k) {
    ShellSeed& sd = seeds[first + k];
    sd.normal = sample.normals[k];
    sd.area = sample.areas[k];
    if (body.fibre_direction)
      sd.fibre = *body.fibre_direction;
    else if (!sample.fibres.empty())
      sd.fibre = sample.fibres[k];
    if (fibred && (sd.fibre - sd.fibre.dot(sd.normal) * sd.normal).norm() < 1e-3)
      throw SetupError(where + ".fibre_direction: along the sheet's normal at particle " + std::to_string(k) +
                       " (the fibres lie in the sheet)");
    if (!sample.pinned.empty() && sample.pinned[k]) sd.support = 2;
    if (!sample.clamped.empty() && sample.clamped[k]) sd.support = 1;
  }
  auto apply = [&](const std::vector<Box>& boxes, const char* key, uint8_t level) {
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      std::size_t held = 0;
      for (std::size_t k = 0; k < n; ++k)
        if (boxes[b].contains(sample.points[k])) {
          ShellSeed& sd = seeds[first + k];
          if (sd.support == 0 || level == 1) sd.support = level;  // fixed wins over pinned
          ++held;
        }
      if (held == 0)
        throw SetupError(where + "." + key + (boxes.size() > 1 ? "[" + std::to_string(b) + "]" : "") +
                         ": the region holds no particle of the body");
    }
  };
  apply(body.shell_pinned, "pinned", 2);
  apply(body.shell_fixed, "fixed", 1);
}

// Shells, sub-cycled within the step (issue 16; the multi-time-step coupling of Zhang, Rezavand & Hu 2021,
// J. Comput. Phys. 429, 110028, as SPHinXsys runs it): the step dt is the fluid's (and other bodies'), and
// the shells take n = ceil(dt / dt_shell) equal sub-steps h = dt / n inside it, with what body_forces() found
// (the fluid's reaction, contact) held over them; the fluid's barrier, stiff against a light sheet, is
// evaluated in each sub-step and the fluid takes its mean (ShellCoupling::barrier_begin). Each sub-step is
// the leapfrog of integrate() on the shells' own velocities (sub_.v, half a sub-step behind the positions):
// the first kick spans the last sub-step of the previous step and this one, (h_prev + h) / 2, the others h.
// What the fluid sees of a shell particle is its end position, its mean velocity over the step (the mean of
// the sub-steps' velocities, (x(t + dt) - x(t)) / dt: the half-step velocity of the fluid's own leapfrog) in
// P.v, and its mean acceleration in P.a. With n = 1 this is the plain leapfrog of integrate(), bit for bit.
void World::step_shells(double dt) {
  const std::size_t ns = shells_.size();
  if (sub_.v.size() != ns) {  // the first step (or a checkpoint without this state): from P.v
    sub_.v.resize(ns);
    sub_.max_speed = 0.0;
    for (std::size_t s = 0; s < ns; ++s) {
      sub_.v[s] = P_.v[shells_.at(s)];
      sub_.max_speed = std::max(sub_.max_speed, sub_.v[s].norm());
    }
    sub_.max_accel = gravity_.norm();
    sub_.last_h = last_dt_;
  }
  const int n = std::max(1, static_cast<int>(std::ceil(dt / shell_stable_dt() * (1.0 - 1e-12))));
  const double h = dt / n;
  std::vector<Vec3> held(ns), vsum(ns, Vec3::Zero()), asum(ns, Vec3::Zero()), barrier;
  std::vector<double> v2(ns, 0.0), a2(ns, 0.0);
  parallel_for(ns, [&](std::size_t s) { held[s] = force_[shells_.at(s)]; });
  // The fluid's barrier (ShellCoupling::barrier_begin) in every sub-step: the pairs that can come within its
  // reach while the sheets move by up to a quarter spacing plus twice their fastest speed over the step.
  const bool bar = coupling_.active() && !barrier_modulus_.empty();
  if (bar)
    coupling_.barrier_begin(P_, shells_, ctx_.periodic, barrier_modulus_,
                            0.25 * scene_.spacing + 2.0 * sub_.max_speed * dt);
  if (contact_in_substeps_) shell_contact_.gather(P_, nb_, shells_, ctx_.periodic);
  for (int k = 0; k < n; ++k) {
    const double kick = k == 0 && sub_.last_h > 0.0 ? 0.5 * (sub_.last_h + h) : h;
    if (bar) coupling_.barrier_substep(P_, shells_, ctx_.periodic, barrier_modulus_, sub_.v, h, barrier);
    shell_substep(h, kick, time_ + k * h, held, bar ? &barrier : nullptr);
    parallel_for(ns, [&](std::size_t s) {
      const uint32_t i = shells_.at(s);
      vsum[s] += sub_.v[s];
      asum[s] += P_.a[i];
      v2[s] = std::max(v2[s], sub_.v[s].squaredNorm());
      a2[s] = std::max(a2[s], P_.a[i].squaredNorm());
    });
  }
  parallel_for(ns, [&](std::size_t s) {
    const uint32_t i = shells_.at(s);
    P_.v[i] = vsum[s] / static_cast<double>(n);
    P_.a[i] = asum[s] / static_cast<double>(n);
  });
  if (bar) coupling_.barrier_end(P_, dt);  // the fluid's share: its mean over the sub-steps
  const auto max = [](double a, double b) { return std::max(a, b); };
  sub_.max_speed = std::sqrt(parallel_reduce(
      ns, 0.0, [&](std::size_t s) { return v2[s]; }, max));
  sub_.max_accel = std::max(std::sqrt(parallel_reduce(
                                ns, 0.0, [&](std::size_t s) { return a2[s]; }, max)),
                            gravity_.norm());
  sub_.last_h = h;
  sub_.last_n = n;
  sub_.substeps += n;
}

// One shell sub-step of length h at time t: resultants, internal forces and director moments
// (Shells::update), plus the held forces, the fluid's barrier at the sheet's current position (`barrier`, by
// slot, or null), gravity, the body's pressure load p(t) A n along the current normal
// and the material's damping; then velocity, position and director (their leapfrog). Supported particles hold
// their position (and, fixed, their director).
void World::shell_substep(double h, double kick, double t, const std::vector<Vec3>& held,
                          const std::vector<Vec3>* barrier) {
  shells_.update(P_, &sub_.v);  // sub_.v, half a sub-step behind: the viscous shells' strain rate
  // Shell contact at the sheets' positions, directors and velocities of this sub-step (contact_in_substeps_).
  if (contact_in_substeps_) {
    contact_f_.resize(P_.size());
    parallel_for(shells_.size(), [&](std::size_t s) { contact_f_[shells_.at(s)] = Vec3::Zero(); });
    shell_contact_.add_listed_forces(P_, shells_, ctx_.periodic, contact_f_, &sub_.v);
  }
  std::vector<double> pressure(bodies_.size(), 0.0);
  for (std::size_t b = 0; b < bodies_.size(); ++b)
    if (scene_.bodies[b].pressure_load) pressure[b] = scene_.bodies[b].pressure_load->at(t);
  const Periodic& per = ctx_.periodic;
  parallel_for(shells_.size(), [&](std::size_t s) {
    const uint32_t i = shells_.at(s);
    Vec3& v = sub_.v[s];
    if (shells_.support(s) == 1 || shells_.support(s) == 2) {
      P_.a[i] = Vec3::Zero();
      v = Vec3::Zero();
      return;
    }
    Vec3 f = held[s] + shells_.internal_force(s) + pressure[P_.body[i]] * shells_.area(s) * shells_.normal(s);
    if (barrier) f += (*barrier)[s];
    if (contact_in_substeps_) f += contact_f_[i];
    P_.a[i] = f / shells_.mass(s) + gravity_ - shells_.damping(s) * v;
    if (shells_.support(s) >= 3) {  // a diaphragm (validations): held in the plane across free_axis
      const Vec3& ax = shells_.free_axis(s);
      P_.a[i] = P_.a[i].dot(ax) * ax;
      v = v.dot(ax) * ax;
    }
    v += kick * P_.a[i];
    P_.x[i] += h * v;
    if (per.any) per.wrap(P_.x[i]);
  });
  shells_.advance_directors(h, kick);
}

double World::shell_stable_dt() const {
  double dt = shells_.stable_dt(scene_.cfl, sub_.max_speed);
  // Shell contact in the sub-steps (contact_in_substeps_): its spring, damper and closing time
  // (ShellContact::stable_dt) at the sheets' sub-step velocities bound the sub-step, not the fluid's step,
  // and no sheet moves more than a quarter of the thinnest sheet's thickness in one sub-step (the contact is
  // evaluated once per sub-step). Issue 18 item 3: the contact's bound applies to the contacting particles
  // only. (In the physio scene it had set the fluid's step: 6.0-6.5 us against the acoustic 7.1 us, stops
  // 46-47.)
  if (contact_in_substeps_) {
    if (lists_valid_ && nb_.size() == P_.size())
      dt = std::min(dt, shell_contact_.stable_dt(P_, nb_, shells_, ctx_.periodic, scene_.cfl,
                                                 sub_.v.size() == shells_.size() ? &sub_.v : nullptr));
    if (sub_.max_speed > 0.0) dt = std::min(dt, 0.25 * min_shell_thickness_ / sub_.max_speed);
  }
  // Force limit (Monaghan 1992) on the shells' own accelerations.
  if (sub_.max_accel > 0.0) dt = std::min(dt, 0.25 * std::sqrt(kernel_.h / sub_.max_accel));
  return dt;
}

// Rigid bodies, eqs. (19)-(22): the per-particle forces of body_forces() summed per body in array order (the
// same order for any thread count), plus gravity; then each body advances and its particles follow. The
// particles' acceleration, which the wall boundary needs (Adami et al. 2012, eq. 27), is their change of
// velocity over the step.
void World::step_rigid(double dt) {
  const std::size_t n = P_.size();
  for (RigidBody& b : rigid_) {
    b.force = b.mass * gravity_;
    b.torque = Vec3::Zero();
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (P_.kind[i] != Kind::Rigid) continue;
    RigidBody& b = rigid_[bodies_[P_.body[i]].rigid];
    b.force += force_[i];
    b.torque += (P_.x[i] - b.com).cross(force_[i]) + moment_[i];
  }
  for (RigidBody& b : rigid_) advance_rigid_body(b, dt, kick_length(dt));
  parallel_for(n, [&](std::size_t i) {
    if (P_.kind[i] != Kind::Rigid) return;
    const RigidBody& b = rigid_[bodies_[P_.body[i]].rigid];
    P_.x[i] = b.position_of(P_.x0[i]);
    const Vec3 v = b.velocity() + b.omega().cross(P_.x[i] - b.com);
    P_.a[i] = (v - P_.v[i]) / dt;
    P_.v[i] = v;
  });
}

void World::check_and_remove(double dt) {
  const std::size_t n = P_.size();
  const double limit2 = speed_limit_ * speed_limit_;
  // First offending particle (smallest index): the same answer for any thread count.
  const std::size_t bad = parallel_reduce(
      n, n,
      [&](std::size_t i) {
        const bool finite = P_.x[i].allFinite() && P_.v[i].allFinite() && std::isfinite(P_.rho[i]);
        return (!finite || P_.v[i].squaredNorm() > limit2) ? i : n;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
  if (bad < n) {
    std::ostringstream msg;
    const bool finite = P_.x[bad].allFinite() && P_.v[bad].allFinite() && std::isfinite(P_.rho[bad]);
    msg << "unstable at t = " << time_ + dt << " s, step " << steps_ + 1 << " (dt = " << dt
        << " s): particle " << P_.id[bad] << " of body '" << scene_.bodies[P_.body[bad]].name << "' at "
        << fmt_vec(P_.x[bad])
        << (finite ? " moves at " + std::to_string(P_.v[bad].norm()) + " m/s, over the limit of " +
                         std::to_string(speed_limit_) + " m/s (time.max_speed)"
                   : " has a non-finite position, velocity or density");
    throw InstabilityError(msg.str());
  }

  // Density error: a weakly compressible fluid stays within a few per cent of its rest density; far beyond
  // that the pressure has blown up (time step too large, sound speed too low for the flow).
  if (scene_.max_density_error > 0.0) {
    const double limit = scene_.max_density_error;
    const std::size_t over = parallel_reduce(
        n, n,
        [&](std::size_t i) {
          // Density summation (eq. 11) makes free-surface particles under-dense by design: not checked.
          if (P_.kind[i] != Kind::Fluid || fluid_[P_.material[i]].summation) return n;
          return std::abs(P_.rho[i] / fluid_[P_.material[i]].rho0 - 1.0) > limit ? i : n;
        },
        [](std::size_t a, std::size_t b) { return std::min(a, b); });
    if (over < n) {
      std::ostringstream msg;
      msg << "unstable at t = " << time_ + dt << " s, step " << steps_ + 1 << " (dt = " << dt
          << " s): particle " << P_.id[over] << " of body '" << scene_.bodies[P_.body[over]].name << "' at "
          << fmt_vec(P_.x[over]) << " has density " << P_.rho[over] << " kg/m^3, a density error of "
          << std::abs(P_.rho[over] / fluid_[P_.material[over]].rho0 - 1.0) << ", over the limit of " << limit
          << " (time.max_density_error)";
      throw InstabilityError(msg.str());
    }
  }

  // Particles that leave the domain are removed; more than the allowed fraction is an instability. (Buffer
  // particles departed past a far face are removed at the next list build, wherever they are.)
  const Box& dom = scene_.domain;
  auto inside = [&](std::size_t i) { return dom.contains(P_.x[i]) || OpenBoundaries::departed(P_, i); };
  const std::size_t outside = parallel_reduce(
      n, std::size_t{0}, [&](std::size_t i) { return std::size_t{!inside(i)}; },
      [](std::size_t a, std::size_t b) { return a + b; });
  if (outside == 0) return;
  std::vector<uint32_t> keep;
  keep.reserve(n - outside);
  std::size_t first_out = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (inside(i))
      keep.push_back(static_cast<uint32_t>(i));
    else if (first_out == n)
      first_out = i;
  }
  left_domain_ += outside;
  const double allowed = scene_.max_leave_fraction * static_cast<double>(moving_at_start_);
  if (static_cast<double>(left_domain_) > allowed) {
    std::ostringstream msg;
    msg << "unstable at t = " << time_ + dt << " s, step " << steps_ + 1 << ": " << left_domain_
        << " particle(s) left the domain (allowed: " << static_cast<std::size_t>(allowed)
        << ", domain.max_leave_fraction = " << scene_.max_leave_fraction << "); first: particle "
        << P_.id[first_out] << " of body '" << scene_.bodies[P_.body[first_out]].name << "' at "
        << fmt_vec(P_.x[first_out]);
    throw InstabilityError(msg.str());
  }
  permute(keep);
  lists_valid_ = false;  // the lists refer to the old indices
}

double World::max_density_error() const {
  return parallel_reduce(
      P_.size(), 0.0,
      [&](std::size_t i) {
        if (P_.kind[i] != Kind::Fluid) return 0.0;
        return std::abs(P_.rho[i] / fluid_[P_.material[i]].rho0 - 1.0);
      },
      [](double a, double b) { return std::max(a, b); });
}

VolumeCheck World::fluid_volume_check() const {
  // The Verlet lists when they hold every particle (none appended since the build): they cover the support.
  const bool lists = lists_valid_ && listed_ == P_.size();
  return aortasph::fluid_volume_check(P_, kernel_, nb_.periodic(), lists ? &nb_ : nullptr);
}

std::size_t World::memory_bytes() const {
  const std::size_t per =
      sizeof(Vec3) * 5 + sizeof(double) * 4 + sizeof(Kind) + 2 * sizeof(uint16_t) + sizeof(uint32_t);
  return per * P_.x.capacity() + nb_.bytes();
}

// Checkpoint sections. Each reader checks sizes against this World (built from the same scene), so a
// checkpoint of another scene is refused rather than misread.
void World::save_state(StateWriter& out) const {
  SectionWriter& w = out.section("world", 1);
  w.value(time_);
  w.value(steps_);
  w.value(last_dt_);
  w.value(max_speed_);
  w.value(max_accel_);
  w.value(static_cast<uint64_t>(left_domain_));
  w.value(static_cast<uint64_t>(moving_at_start_));
  for (const auto& [name, sec] : profile_.phases()) w.value(sec);

  SectionWriter& p = out.section("particles", 2);  // 2: with the shift (Particles::shift; stop 44)
  p.value(static_cast<uint64_t>(P_.size()));
  P_.for_each_array([&](const char* name, const auto& array) {
    p.string(name);
    p.array(array);
  });

  SectionWriter& r = out.section("rigid", 1);
  r.value(static_cast<uint64_t>(rigid_.size()));
  for (const RigidBody& b : rigid_) {
    r.value(b.body);
    r.vec3(b.com);
    r.value(b.q.w());
    r.vec3(b.q.vec());
    r.vec3(b.P);
    r.vec3(b.L);
  }

  SectionWriter& ob = out.section("open_boundaries", 1);
  const OpenBoundaryState& os = open_.state();
  ob.value(os.next_id);
  for (double v : {os.volume_in, os.volume_out, os.mass_in, os.mass_out}) ob.value(v);
  ob.value(os.created);
  ob.value(os.removed);

  // Per open boundary: flow, averaging interval, imposed pressure, Windkessel state (issue 17). A section of
  // its own, so that checkpoints written before it still load (their boundaries keep the values of t = 0).
  SectionWriter& of = out.section("open_boundary_flows", 1);
  of.value(open_.interval_start());
  of.value(static_cast<uint64_t>(open_.flows().size()));
  for (const OpenBoundaryFlow& f : open_.flows())
    for (double v :
         {f.flow, f.interval_volume, f.pressure, f.windkessel.pc, f.windkessel.q, f.windkessel.p_out})
      of.value(v);
  if (open_.non_reflecting()) {  // the waves of non-reflecting boundaries: a section of its own (issue 17)
    SectionWriter& ow = out.section("open_boundary_waves", 1);
    ow.value(static_cast<uint64_t>(open_.flows().size()));
    for (const OpenBoundaryFlow& f : open_.flows())
      for (double v : {f.wave_ref, f.wave_p}) ow.value(v);
  }

  // The Verlet lists are rebuilt from the positions of their last build (and the rebuild and sort schedule
  // continues from builds_), so the resumed run sees the very lists the saved one had.
  // Shells: the directors and their spin, by shell slot (the reference is rebuilt from the scene).
  SectionWriter& sh = out.section("shells", 1);
  sh.array(shells_.directors());
  sh.array(shells_.omegas());
  if (!shells_.empty()) {  // the last update's inputs (Shells::restore_update): a section of its own
    SectionWriter& su = out.section("shell_update", 1);
    su.array(shells_.update_positions());
    su.array(shells_.update_directors());
  }
  if (shells_.stiffens()) {  // a section of its own: only stiffening (Lee-Sacks) shells have it
    SectionWriter& sf = out.section("shell_stiffening", 1);
    sf.array(shells_.stiffening());
  }

  if (!shells_.empty()) {  // shell sub-cycling (step_shells): a section of its own, older checkpoints lack it
    SectionWriter& ss = out.section("shell_subcycle", 1);
    for (double v : {sub_.last_h, sub_.max_speed, sub_.max_accel}) ss.value(v);
    ss.value(sub_.substeps);
    ss.value(sub_.last_n);
    ss.array(sub_.v);
  }

  if (coupling_.active()) {  // a section of its own: older checkpoints and shell-free scenes lack it
    SectionWriter& sc = out.section("shell_coupling", 1);
    sc.value(coupling_.crossings());
    if (coupling_.label_disagreements() > 0) {  // a section of its own: older checkpoints lack it
      SectionWriter& sd = out.section("shell_label_disagreements", 1);
      sd.value(coupling_.label_disagreements());
    }
    if (mask_density_on_) {  // the last step's masks (boundary/mask_density.hpp)
      SectionWriter& sm = out.section("shell_masks", 1);
      sm.array(mask_density_.ids());
      sm.array(mask_density_.offsets());
      sm.array(mask_density_.rows());
    }
  }

  SectionWriter& nb = out.section("neighbors", 1);
  nb.value(lists_valid_);
  nb.value(builds_);
  nb.array(lists_valid_ ? build_positions() : std::vector<Vec3>{});
  if (lists_valid_ && listed_ < P_.size()) {  // particles appended since the build (append_to_lists)
    SectionWriter& nr = out.section("neighbor_rows", 1);
    nr.value(static_cast<uint64_t>(listed_));
  }
}

void World::load_state(const StateReader& in) {
  SectionReader w = in.section("world");
  time_ = w.value<double>();
  steps_ = w.value<long>();
  last_dt_ = w.value<double>();
  max_speed_ = w.value<double>();
  max_accel_ = w.value<double>();
  left_domain_ = static_cast<std::size_t>(w.value<uint64_t>());
  const auto moving = w.value<uint64_t>();
  if (moving != moving_at_start_) w.mismatch("moving particles at t = 0", moving, moving_at_start_);
  for (double* sec : profile_.slots()) *sec = w.value<double>();  // the order save_state wrote
  w.done();

  SectionReader p = in.section("particles");
  const auto n = static_cast<std::size_t>(p.value<uint64_t>());
  // Particles leave the domain; open boundaries also create them, so only scenes without one bound n.
  if (open_.empty() && n > P_.size()) p.mismatch("particles", n, P_.size());
  P_.for_each_array([&](const char* name, auto& array) {
    if (p.version() < 2 && Particles::optional(name)) {  // written before the array existed: none shifted yet
      array.clear();
      return;
    }
    const std::string stored = p.string();
    if (stored != name)
      throw SetupError("checkpoint section 'particles': array '" + stored + "' where '" + name +
                       "' was expected (another layout)");
    array.clear();
    p.array(array, name, Particles::optional(name) ? SIZE_MAX : n);
    if (!array.empty() && array.size() != n) p.mismatch(name, array.size(), n);
  });
  p.done();
  if (shifting_ && P_.shift.empty()) P_.shift.assign(n, Vec3::Zero());
  for (std::size_t i = 0; i < n; ++i)
    if (P_.body[i] >= bodies_.size() || P_.material[i] >= scene_.materials.size() ||
        static_cast<uint8_t>(P_.kind[i]) > static_cast<uint8_t>(Kind::Shell))
      throw SetupError("checkpoint section 'particles': particle " + std::to_string(i) +
                       " refers to a body or material this scene does not have");

  SectionReader r = in.section("rigid");
  const auto nr = r.value<uint64_t>();
  if (nr != rigid_.size()) r.mismatch("rigid bodies", nr, rigid_.size());
  for (RigidBody& b : rigid_) {
    if (r.value<int>() != b.body) throw SetupError("checkpoint section 'rigid': bodies in another order");
    b.com = r.vec3();
    const double qw = r.value<double>();
    const Vec3 qv = r.vec3();
    b.q = Eigen::Quaterniond(qw, qv.x(), qv.y(), qv.z());
    b.P = r.vec3();
    b.L = r.vec3();
  }
  r.done();

  SectionReader ob = in.section("open_boundaries");
  OpenBoundaryState& os = open_.state();
  os.next_id = ob.value<uint32_t>();
  for (double* v : {&os.volume_in, &os.volume_out, &os.mass_in, &os.mass_out}) *v = ob.value<double>();
  os.created = ob.value<uint64_t>();
  os.removed = ob.value<uint64_t>();
  ob.done();

  if (in.has("open_boundary_flows")) {
    SectionReader of = in.section("open_boundary_flows");
    open_.interval_start() = of.value<double>();
    const auto nf = of.value<uint64_t>();
    if (nf != open_.flows().size()) of.mismatch("open boundaries", nf, open_.flows().size());
    for (OpenBoundaryFlow& f : open_.flows())
      for (double* v :
           {&f.flow, &f.interval_volume, &f.pressure, &f.windkessel.pc, &f.windkessel.q, &f.windkessel.p_out})
        *v = of.value<double>();
    of.done();
  }
  if (in.has("open_boundary_waves")) {
    SectionReader ow = in.section("open_boundary_waves");
    const auto nw = ow.value<uint64_t>();
    if (nw != open_.flows().size()) ow.mismatch("open boundaries", nw, open_.flows().size());
    for (OpenBoundaryFlow& f : open_.flows())
      for (double* v : {&f.wave_ref, &f.wave_p}) *v = ow.value<double>();
    ow.done();
  }
  if (in.has("shells") || !shells_.empty()) {
    SectionReader sh = in.section("shells");
    sh.array(shells_.directors(), "shell directors", shells_.size());
    sh.array(shells_.omegas(), "shell angular velocities", shells_.size());
    sh.done();
  }
  // The stiffening of the last sub-step's update (at the positions it started from): set after the update
  // below, which measures it at the stored positions.
  std::vector<double> stiffening;
  if (in.has("shell_stiffening")) {
    SectionReader sf = in.section("shell_stiffening");
    sf.array(stiffening, "shell stiffening", shells_.size());
    sf.done();
  }
  sub_ = ShellSubcycle{};  // without the section: rebuilt from P.v at the next step
  if (in.has("shell_subcycle")) {
    SectionReader ss = in.section("shell_subcycle");
    for (double* v : {&sub_.last_h, &sub_.max_speed, &sub_.max_accel}) *v = ss.value<double>();
    sub_.substeps = ss.value<long>();
    sub_.last_n = ss.value<int>();
    ss.array(sub_.v, "shell sub-cycle velocities");
    ss.done();
    if (!sub_.v.empty() && sub_.v.size() != shells_.size())
      ss.mismatch("shell sub-cycle velocities", sub_.v.size(), shells_.size());
  }

  SectionReader nb = in.section("neighbors");
  lists_valid_ = nb.value<bool>();
  builds_ = nb.value<long>();
  std::vector<Vec3> x_at_build;
  nb.array(x_at_build, "x_at_build");
  nb.done();
  if (lists_valid_) {
    if (x_at_build.size() != n) nb.mismatch("x_at_build", x_at_build.size(), n);
    // The lists as built: over the particles that existed then, those appended since with empty rows.
    listed_ = n;
    if (in.has("neighbor_rows")) {
      SectionReader nr = in.section("neighbor_rows");
      listed_ = static_cast<std::size_t>(nr.value<uint64_t>());
      nr.done();
      if (listed_ > n) nr.mismatch("listed particles", listed_, n);
    }
    std::vector<uint8_t> fixed = fixed_mask();
    fixed.resize(listed_);
    nb_.build(
        std::vector<Vec3>(x_at_build.begin(), x_at_build.begin() + static_cast<std::ptrdiff_t>(listed_)),
        kernel_.support + skin_, fixed);
    nb_.append_rows(n - listed_);
    coupling_.on_build(P_, nb_);
    record_build_positions(x_at_build);
  }
  if (in.has("shell_coupling")) {
    SectionReader sc = in.section("shell_coupling");
    coupling_.set_crossings(sc.value<long>());
    sc.done();
  }
  if (in.has("shell_label_disagreements")) {
    SectionReader sd = in.section("shell_label_disagreements");
    coupling_.set_label_disagreements(sd.value<long>());
    sd.done();
  }
  mask_density_ = MaskDensity{};  // without the section: the first step counts no change of the masks
  if (in.has("shell_masks")) {
    SectionReader sm = in.section("shell_masks");
    std::vector<uint32_t> ids, offsets, rows;
    sm.array(ids, "shell mask ids");
    sm.array(offsets, "shell mask offsets", ids.size() + 1);
    sm.array(rows, "shell mask rows", offsets.empty() ? 0 : offsets.back());
    sm.done();
    if (offsets[0] != 0) sm.mismatch("shell mask offsets", offsets[0], 0);
    for (std::size_t r = 0; r < ids.size(); ++r)
      if (offsets[r] > offsets[r + 1]) sm.mismatch("shell mask offsets", offsets[r], offsets[r + 1]);
    mask_density_.restore(std::move(ids), std::move(offsets), std::move(rows));
  }

  // The solid's reference configuration is rebuilt from the scene (it never changes); only its map from
  // particle slots to particle indices follows the stored order, and its stress the stored positions.
  if (!solids_.empty()) {
    solids_.reindex(P_);
    solids_.update_stress(P_);
  }
  if (!shells_.empty()) {
    shells_.reindex(P_);
    if (in.has("shell_update")) {  // the last update again, from its own positions and directors
      SectionReader su = in.section("shell_update");
      std::vector<Vec3> x, d;
      su.array(x, "shell update positions", shells_.size());
      su.array(d, "shell update directors", shells_.size());
      su.done();
      if (x.size() != shells_.size()) su.mismatch("shell update positions", x.size(), shells_.size());
      if (d.size() != shells_.size()) su.mismatch("shell update directors", d.size(), shells_.size());
      shells_.restore_update(std::move(x), std::move(d));  // the stiffening of that update too
    } else {  // older checkpoints: from the positions now (the resumed run differs in the last digits)
      shells_.update(P_);
      if (!stiffening.empty()) shells_.stiffening() = stiffening;
    }
  }
}

Snapshot World::snapshot(const std::string& field, int frame) const {
  return snapshot(std::vector<std::string>{field}, frame);
}

Snapshot World::snapshot(const std::vector<std::string>& fields, int frame) const {
  Snapshot s;
  s.time = time_;
  s.frame = frame;
  s.spacing = scene_.spacing;
  const std::size_t n = P_.size();
  s.position.resize(3 * n);
  s.body.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) s.position[3 * i + d] = static_cast<float>(P_.x[i][d]);
    s.body[i] = P_.body[i];
  }
  // Each distinct field once, in the order asked.
  for (const std::string& field : fields) {
    if (field == "material" || s.field(field)) continue;
    SnapshotField& f = s.fields.emplace_back();
    f.name = field;
    f.values.resize(n, 0.0f);
    f.unit = field_unit(field);
    if (field == "speed") {
      for (std::size_t i = 0; i < n; ++i) f.values[i] = static_cast<float>(P_.v[i].norm());
    } else if (field == "pressure") {
      for (std::size_t i = 0; i < n; ++i) f.values[i] = static_cast<float>(P_.p[i]);
    } else if (field == "displacement") {
      for (std::size_t i = 0; i < n; ++i) f.values[i] = static_cast<float>((P_.x[i] - P_.x0[i]).norm());
    } else if (field == "stress") {  // von Mises stress of elastic particles; zero elsewhere
      for (std::size_t k = 0; k < solids_.size(); ++k)
        f.values[solids_.at(k)] = static_cast<float>(solids_.von_mises(k));
      for (std::size_t k = 0; k < shells_.size(); ++k)  // shells: the largest over the Gauss points
        f.values[shells_.at(k)] = static_cast<float>(shells_.von_mises(k));
    }
  }
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const Body& body = scene_.bodies[b];
    BodyView view;
    view.name = body.name;
    view.type = bodies_[b].type;
    if (body.color)
      view.color = {static_cast<float>((*body.color)[0]), static_cast<float>((*body.color)[1]),
                    static_cast<float>((*body.color)[2])};
    else
      view.color = default_color(view.type);
    view.render = body.render;
    view.mesh = bodies_[b].mesh;  // fixed walls: the mesh of t = 0 is the mesh now
    s.bodies.push_back(std::move(view));
  }
  // Shell bodies: their sheet, by the particles' indices now.
  const auto& tri = sheets_.triangles();
  for (std::size_t t = 0; t < tri.size(); ++t)
    s.bodies[sheets_.body()[t]].sheet.push_back(
        {shells_.at(tri[t][0]), shells_.at(tri[t][1]), shells_.at(tri[t][2])});
  return s;
}

}  // namespace aortasph
