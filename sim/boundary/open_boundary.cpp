#include "boundary/open_boundary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "geometry/shapes.hpp"

namespace aortasph {

namespace {

std::string where(std::size_t k, const OpenBoundarySpec& s) {
  return "open_boundaries[" + std::to_string(k) + "] '" + s.name + "'";
}

// What the serial pass does with a particle.
enum Action : uint8_t {
  kNone = 0,
  kInflowToFluid,   // crossed the inlet disc: becomes fluid, a new buffer particle is created behind
  kFluidToOutflow,  // crossed the outlet disc
  kOutflowToFluid,  // came back across the outlet disc
  kRemove,          // passed the outflow buffer's far face, or left a buffer sideways
  kDepart,          // passed a deep buffer's far face: mass 0, removed at the next list build
  kRemoveBackflow,  // fluid that flowed back into an inflow buffer
  kFluidToInflow,   // fluid that crossed a pressure inlet's disc backwards
};

// A pressure inlet's column may reach this far (in spacings) beyond its buffer's far face: a column stretched
// a little (its particles move with slightly different carried velocities) keeps its `layers` particles.
constexpr double kFarSlack = 0.25;
// A particle added at a pressure inlet column's front keeps this far (in spacings) from the fluid.
constexpr double kFrontRoom = 0.75;
// A pressure inlet's lattice column keeps at least this far (in spacings, across the axis) from every body
// particle beside its buffer (see clear_columns).
constexpr double kColumnClearance = 0.9;

}  // namespace

double OpenBoundaries::prescribed_pressure(std::size_t k, double t) const {
  const Zone& z = zones_[k];
  if (z.spec.type == OpenBoundaryType::Inflow) return z.spec.inlet_pressure.at(t);
  if (z.spec.windkessel) return flows_[k].windkessel.p_out;
  return z.spec.pressure.at(t);
}

std::vector<OpenBoundaries::SlabSums> OpenBoundaries::slab_sums(const Particles& P) const {
  // The fluid in a slab one kernel support L deep on the domain's side of each disc, with the smooth window
  // w(d) = sin^2(pi d / L) (open_boundary.hpp): sum V (v . n) w and sum V w, in one pass per zone.
  const std::size_t n = P.size();
  const double L = support_, pi = 3.14159265358979323846;
  std::vector<SlabSums> out(zones_.size());
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    const double side = z.spec.type == OpenBoundaryType::Inflow ? 1.0 : -1.0;
    out[k] = parallel_reduce(
        n, SlabSums{},
        [&](std::size_t i) {
          if (P.kind[i] != Kind::Fluid) return SlabSums{};
          const double d = side * z.axial(P.x[i]);
          if (d <= 0.0 || d >= L || z.radial(P.x[i]) >= z.spec.radius) return SlabSums{};
          const double w = std::sin(pi * d / L);
          return SlabSums{P.m[i] / P.rho[i] * P.v[i].dot(z.spec.normal) * w * w, P.m[i] / P.rho[i] * w * w};
        },
        [](const SlabSums& x, const SlabSums& y) {
          return SlabSums{x.flux + y.flux, x.weight + y.weight};
        });
  }
  return out;
}

double OpenBoundaries::slab_flow(const SlabSums& s) const {
  return s.flux / (0.5 * support_);  // the volume flux through the disc (open_boundary.hpp)
}

double OpenBoundaries::slab_velocity(const SlabSums& s) {
  return s.weight > 0.0 ? s.flux / s.weight : 0.0;  // the window's volume-weighted mean of v . n
}

double OpenBoundaries::Zone::inflow_speed(const Vec3& x, double t) const {
  const double V = spec.velocity.at(t);
  if (!spec.parabolic) return V;
  // Poiseuille profile V (1 - r^2/R^2) / mean(1 - r^2/R^2): its mean over the inlet's columns is V.
  const double r = radial(x) / spec.radius;
  return V * std::max(1.0 - r * r, 0.0) / profile_mean;
}

void OpenBoundaries::configure(const Scene& scene, const std::vector<FluidParams>& fluid) {
  fluid_ = fluid;
  dx_ = scene.spacing;
  support_ = 2.0 * scene.smoothing_ratio * scene.spacing;
  // Probe rows come every time.probe_interval (a whole fraction of output_interval; a scene built in code may
  // leave probe_interval at its default and set only output_interval, hence the smaller of the two). Until
  // stop 63 the interval was output_interval: with rows between the frames (the physio scene's 1 ms rows, 10
  // ms frames) a row's boundary flow was the mean since the last frame.
  row_interval_ = std::min(scene.output_interval, scene.probe_interval);
  const double dx = dx_;
  zones_.clear();
  for (std::size_t k = 0; k < scene.open_boundaries.size(); ++k) {
    const OpenBoundarySpec& s = scene.open_boundaries[k];
    Zone z;
    z.spec = s;
    z.spec.normal = s.normal.normalized();
    perpendicular_frame(z.spec.normal, z.u, z.v);
    z.depth = s.layers * dx;
    // The buffer must lie inside the domain, an outflow's with one more layer (particles pass its far face
    // before they are removed), or particles would count as leaving the domain.
    const double far = s.type == OpenBoundaryType::Inflow ? -z.depth : z.depth + dx;
    for (const double a : {0.0, far})
      for (int c = 0; c < 4; ++c) {
        const double ang = c * 0.5 * 3.14159265358979323846;
        const Vec3 x = s.point + a * z.spec.normal + s.radius * (std::cos(ang) * z.u + std::sin(ang) * z.v);
        if (!scene.domain.contains(x))
          throw SetupError(where(k, s) + ": the buffer (" + std::to_string(s.layers) +
                           " layers) reaches outside the domain");
      }
    if (s.type == OpenBoundaryType::Outflow)  // the fluid that leaves: the first fluid body's material
      for (const Body& b : scene.bodies)
        if (scene.materials.at(b.material).type == MaterialType::Fluid) {
          z.material = b.material;
          break;
        }
    if (s.type == OpenBoundaryType::Inflow) {
      if (s.body < 0 || s.body >= static_cast<int>(scene.bodies.size()) ||
          scene.materials.at(scene.bodies[s.body].material).type != MaterialType::Fluid)
        throw SetupError(where(k, s) + ": an inflow must feed a fluid body");
      z.material = scene.bodies[s.body].material;
      // Lattice columns across the disc, laid out like the tube's (shapes.cpp), so that an inlet at a tube's
      // base continues the tube's lattice.
      const int nr = static_cast<int>(std::ceil(s.radius / dx));
      z.column_nr = nr;
      for (int j = -nr; j < nr; ++j)
        for (int i = -nr; i < nr; ++i) {
          const double a = (i + 0.5) * dx, b = (j + 0.5) * dx;
          if (std::hypot(a, b) < s.radius) z.columns.push_back(s.point + a * z.u + b * z.v);
        }
      if (z.columns.empty())
        throw SetupError(where(k, s) + ": radius " + std::to_string(s.radius) +
                         " holds no particle column at spacing " + std::to_string(dx));
      index_columns(z);
    }
    zones_.push_back(z);
  }
}

void OpenBoundaries::setup(const Scene& scene, const std::vector<FluidParams>& fluid, Particles& P) {
  configure(scene, fluid);
  const double dx = dx_;
  uint32_t next = 0;
  for (std::size_t i = 0; i < P.size(); ++i) next = std::max(next, P.id[i] + 1);
  state_ = OpenBoundaryState{};
  state_.next_id = next;

  // Fluid that starts behind an inlet disc (a fluid body filling the inlet tube to its end) gives way to the
  // inflow buffer: fluid particles within the buffer's slab and one kernel support behind it (up to a quarter
  // spacing in front of the disc), within the disc's radius plus a spacing, are removed before the buffer is
  // laid.
  {
    std::vector<uint32_t> keep;
    keep.reserve(P.size());
    for (std::size_t i = 0; i < P.size(); ++i) {
      bool behind = false;
      if (P.kind[i] == Kind::Fluid)
        for (const Zone& z : zones_) {
          if (z.spec.type != OpenBoundaryType::Inflow) continue;
          const double a = z.axial(P.x[i]);
          if (a < 0.25 * dx && a >= -z.depth - support_ && z.radial(P.x[i]) < z.spec.radius + dx)
            behind = true;
        }
      if (!behind) keep.push_back(static_cast<uint32_t>(i));
    }
    if (keep.size() < P.size()) P.permute(keep);
  }

  clear_columns(P);

  // The inflow buffers: `layers` lattice layers behind each inlet disc.
  const std::size_t first_buffer = P.size();
  for (const Zone& z : zones_) {
    if (z.spec.type != OpenBoundaryType::Inflow) continue;
    const FluidParams& fp = fluid_.at(z.material);
    for (int layer = 0; layer < z.spec.layers; ++layer)
      for (const Vec3& c : z.columns) {
        const std::size_t i = P.size();
        P.resize(i + 1);
        P.x[i] = c - (layer + 0.5) * dx * z.spec.normal;
        P.x0[i] = P.x[i];
        P.kind[i] = Kind::Inflow;
        P.body[i] = static_cast<uint16_t>(z.spec.body);
        P.material[i] = static_cast<uint16_t>(z.material);
        P.id[i] = state_.next_id++;
        P.m[i] = fp.rho0 * dx * dx * dx;
        P.rho[i] = fp.rho0;
      }
  }

  // Inflow buffers must not overlap bodies (nor each other): particles closer than half a spacing.
  if (P.size() > first_buffer) {
    NeighborSearch nb;
    nb.build(P.x, 0.5 * dx);
    for (std::size_t i = first_buffer; i < P.size(); ++i)
      for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
        const uint32_t j = nb.index()[k];
        const int zi = zone_of(P.x[i], Kind::Inflow);
        if (j < first_buffer || zone_of(P.x[j], Kind::Inflow) != zi) {
          std::ostringstream msg;
          msg << where(static_cast<std::size_t>(zi), zones_[zi].spec) << ": the inflow buffer overlaps "
              << (j < first_buffer ? "body '" + scene.bodies[P.body[j]].name + "'" : std::string("another"))
              << " near (" << P.x[i].x() << ", " << P.x[i].y() << ", " << P.x[i].z() << ")";
          throw SetupError(msg.str());
        }
      }
  }

  // Fluid that starts beyond an outlet disc is in the outflow buffer from the start (not counted as out).
  for (std::size_t i = 0; i < P.size(); ++i)
    if (P.kind[i] == Kind::Fluid && zone_of(P.x[i], Kind::Outflow) >= 0 &&
        zones_[zone_of(P.x[i], Kind::Outflow)].axial(P.x[i]) >= 0.0)
      P.kind[i] = Kind::Outflow;
  // The flows at t = 0 (the fluid's initial velocity) start the Windkessels.
  flows_.assign(zones_.size(), OpenBoundaryFlow{});
  interval_start_ = 0.0;
  const std::vector<SlabSums> s0 = slab_sums(P);
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const double q0 = slab_flow(s0[k]);
    flows_[k].flow = q0;
    if (zones_[k].spec.windkessel) flows_[k].windkessel = windkessel_start(*zones_[k].spec.windkessel, q0);
  }
  impose(P, scene.gravity, 0.0);
  // Non-reflecting boundaries start without a wave, from the disc velocity or the slab pressure of t = 0.
  for (std::size_t k = 0; k < zones_.size(); ++k)
    if (zones_[k].spec.non_reflecting_tau > 0.0)
      flows_[k].wave_ref = zones_[k].pressure_driven() ? slab_velocity(s0[k]) : flows_[k].pressure;
  for (std::size_t i = first_buffer; i < P.size(); ++i) {
    const Zone& z = zones_[zone_of(P.x[i], Kind::Inflow)];
    // A pressure inlet's buffer starts at rest; from the first step on it moves with the fluid at the disc.
    P.v[i] = z.spec.pressure_inlet ? Vec3(Vec3::Zero()) : Vec3(z.inflow_speed(P.x[i], 0.0) * z.spec.normal);
    P.v_wall[i] = P.v[i];
  }
}

// A pressure inlet's columns keep clear of the bodies beside the buffer: a column in the disc's outermost
// spacing (r >= radius - dx) whose axis passes within kColumnClearance spacings of a body particle (a wall,
// elastic, rigid or shell particle beside the buffer, between its far face and the disc) is dropped. (A
// column farther in that meets a body is an error, as before: the buffer overlaps the body.) The lattice
// columns fill the disc out to its radius, which is right where the wall lies on the same lattice (a tube:
// wall particles at r >= R, 1 spacing or more from the outermost column) but not where it does not: the
// aortic root's wall is rings of particles half a spacing outside the lumen (the blood filling it keeps half
// a spacing inside), so an inlet of the lumen's radius had a ring of columns 0.52-0.6 spacings from the wall.
// Its particles, pushed in by the left-ventricular pressure, entered the wall's first layer above the disc
// from 0.033 s and passed it from 0.052 s (stop 40, physio scene). Velocity inlets keep every column: their
// flow is prescribed per column, and at the rim a Poiseuille profile moves them at a few per cent of the
// mean. Columns depend on the particles at set-up only, so a restored world (built from its scene, then its
// checkpoint) has the same.
void OpenBoundaries::clear_columns(const Particles& P) {
  const double dx = dx_, clear2 = kColumnClearance * kColumnClearance * dx * dx;
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    Zone& z = zones_[k];
    if (z.spec.type != OpenBoundaryType::Inflow || !z.spec.pressure_inlet) continue;
    // The body particles beside the buffer, as (u, v) coordinates on the disc.
    std::vector<Eigen::Vector2d> bodies;
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (fluid_like(P.kind[i])) continue;
      const double a = z.axial(P.x[i]);
      if (a < -z.depth || a > 0.0 || z.radial(P.x[i]) > z.spec.radius + 2.0 * dx) continue;
      const Vec3 r = P.x[i] - z.spec.point;
      bodies.push_back(Eigen::Vector2d(r.dot(z.u), r.dot(z.v)));
    }
    std::erase_if(z.columns, [&](const Vec3& c) {
      const Vec3 r = c - z.spec.point;
      const Eigen::Vector2d q(r.dot(z.u), r.dot(z.v));
      // The rim only (the disc's outermost spacing): a body inside the disc is an overlap, refused below.
      return q.norm() >= z.spec.radius - dx &&
             std::any_of(bodies.begin(), bodies.end(),
                         [&](const Eigen::Vector2d& b) { return (b - q).squaredNorm() < clear2; });
    });
    if (z.columns.empty())
      throw SetupError(where(k, z.spec) + ": every particle column lies within " +
                       std::to_string(kColumnClearance) + " spacings of a body");
    index_columns(z);
  }
}

// Inflow zone z's lattice lookup (column_index), area and mean Poiseuille profile from its columns.
void OpenBoundaries::index_columns(Zone& z) const {
  const double dx = dx_;
  const int nr = z.column_nr;
  z.column_index.assign(static_cast<std::size_t>(4 * nr * nr), -1);
  double sum_profile = 0.0;
  for (std::size_t m = 0; m < z.columns.size(); ++m) {
    const Vec3 r = z.columns[m] - z.spec.point;
    const int i = static_cast<int>(std::floor(r.dot(z.u) / dx)),
              j = static_cast<int>(std::floor(r.dot(z.v) / dx));
    z.column_index[static_cast<std::size_t>((j + nr) * 2 * nr + (i + nr))] = static_cast<int32_t>(m);
    const double rr = std::hypot((i + 0.5) * dx, (j + 0.5) * dx) / z.spec.radius;  // the lattice point's
    sum_profile += 1.0 - rr * rr;
  }
  z.area = static_cast<double>(z.columns.size()) * dx * dx;
  z.profile_mean = sum_profile / static_cast<double>(z.columns.size());
}

int OpenBoundaries::zone_of(const Vec3& x, Kind kind) const {
  // A little slack around each buffer: particles move up to a fraction of a spacing per step.
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    if (z.radial(x) > z.spec.radius + 0.5 * dx_) continue;
    const double a = z.axial(x);
    if (kind == Kind::Inflow && z.spec.type == OpenBoundaryType::Inflow && a >= -z.depth - 0.5 * dx_ &&
        a < 0.5 * dx_)
      return static_cast<int>(k);
    if (kind == Kind::Outflow && z.spec.type == OpenBoundaryType::Outflow && a >= -support_ &&
        a <= z.depth + support_)
      return static_cast<int>(k);
  }
  return -1;
}

double OpenBoundaries::prescribed_inflow_rate(double t) const {
  double q = 0.0;
  for (const Zone& z : zones_)
    if (z.spec.type == OpenBoundaryType::Inflow && !z.spec.pressure_inlet)
      q += z.spec.velocity.at(t) * z.area;
  return q;
}

double OpenBoundaries::pressure_gauge() const {
  double gauge = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    if (z.spec.type == OpenBoundaryType::Inflow && !z.spec.pressure_inlet) continue;  // a velocity inlet
    gauge = std::min(gauge, flows_[k].pressure - fluid_[z.material].p_background);
  }
  return std::isfinite(gauge) ? std::max(gauge, 0.0) : 0.0;
}

void OpenBoundaries::impose(Particles& P, const Vec3& g, double t) {
  const std::size_t n = P.size();
  const double dx3 = dx_ * dx_ * dx_;
  // Inflow pressure: zero gradient along the axis. The volume-weighted mean pressure of the fluid in a slab
  // one kernel support deep inside the disc, applied at the slab's centroid, plus the hydrostatic difference.
  struct Slab {
    double vol = 0.0, pv = 0.0;
    Vec3 xv = Vec3::Zero();
  };
  std::vector<Slab> slab(zones_.size());
  std::vector<double> outlet_p(zones_.size(), 0.0);
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    if (z.pressure_driven()) {
      outlet_p[k] = prescribed_pressure(k, t);
      if (z.spec.non_reflecting_tau > 0.0) outlet_p[k] += flows_[k].wave_p;  // the outgoing wave's part
      flows_[k].pressure = outlet_p[k];
      continue;
    }
    slab[k] = parallel_reduce(
        n, Slab{},
        [&](std::size_t i) {
          if (P.kind[i] != Kind::Fluid || z.radial(P.x[i]) >= z.spec.radius) return Slab{};
          const double a = z.axial(P.x[i]);
          if (a < 0.0 || a >= support_) return Slab{};
          const double vol = P.m[i] / P.rho[i];
          return Slab{vol, vol * P.p[i], vol * P.x[i]};
        },
        [](const Slab& a, const Slab& b) {
          return Slab{a.vol + b.vol, a.pv + b.pv, a.xv + b.xv};
        });
    flows_[k].pressure = slab[k].vol > 0.0 ? slab[k].pv / slab[k].vol : fluid_.at(z.material).p_background;
  }
  parallel_for(n, [&](std::size_t i) {
    if ((P.kind[i] != Kind::Inflow && P.kind[i] != Kind::Outflow) || departed(P, i)) return;
    const int k = zone_of(P.x[i], P.kind[i]);
    if (k < 0) return;
    const Zone& z = zones_[k];
    const FluidParams& fp = fluid_[P.material[i]];
    double p = 0.0;
    if (z.pressure_driven()) {
      p = outlet_p[k] + fp.rho0 * g.dot(P.x[i] - z.spec.point);
    } else if (slab[k].vol > 0.0) {
      p = slab[k].pv / slab[k].vol + fp.rho0 * g.dot(P.x[i] - slab[k].xv / slab[k].vol);
    } else {
      p = fp.p_background;  // no fluid at the inlet yet
    }
    P.rho[i] = fp.density(p);
    P.p[i] = fp.pressure(P.rho[i]);  // density() clamps far-negative pressures: keep the pair consistent
    // Inflow particles sit on the lattice, one per dx^3: their mass follows their density, so that
    // m / rho = dx^3 and the fluid they become has the density its spacing says. (With m = rho0 dx^3 under
    // pressure, each entering particle would claim less volume than it fills, the fluid's density would drift
    // above its particle number density, and the column would push out more than comes in.) The volume flow
    // into the domain is then exactly V A, the mass flow rho V A.
    if (P.kind[i] == Kind::Inflow) P.m[i] = P.rho[i] * dx3;
  });
}

std::size_t OpenBoundaries::append_buffer_particle(Particles& P, const Vec3& x, Kind kind,
                                                   std::optional<std::size_t> src) {
  if (state_.next_id == std::numeric_limits<uint32_t>::max())
    throw InstabilityError("open boundaries: particle ids exhausted");
  const std::size_t j = P.size();
  P.resize(j + 1);  // new entries are zero
  P.x[j] = x;
  P.x0[j] = x;
  P.kind[j] = kind;
  if (src) {
    P.v[j] = P.v[*src];
    P.v_wall[j] = P.v[*src];
    P.rho[j] = P.rho[*src];
    P.p[j] = P.p[*src];
    P.m[j] = P.m[*src];
    P.body[j] = P.body[*src];
    P.material[j] = P.material[*src];
  }
  P.id[j] = state_.next_id++;
  return j;
}

// A pressure inlet's buffer, column by column (Zone::columns): every lattice column holds `layers`
// particles. Its particles move along the column with the velocity carried from the fluid (update), so a
// column stays on its lattice line; where it holds fewer (its front particle became fluid, or in backflow its
// rear one left past the far face), a particle is added, in this order of preference: a spacing behind its
// rear one, when that is still within the buffer (kFarSlack); in the middle of its widest gap, when that is
// 1.5 spacings or more (the carried velocities differ a little along a column, which stretches it); a
// spacing in front of its front one (half a spacing behind the disc in an empty column), when that is a
// quarter spacing or more behind the disc and kFrontRoom from any fluid particle. Fluid that flows back
// across the disc joins the buffer and counts in the column its lateral position falls in, so the column is
// not topped up in front of it. (Until stop 40 an entering particle was replaced `layers` spacings behind
// itself where no buffer particle was within half a spacing: beside the particles that had flowed back into
// the buffer off the lattice, the columns then lost particles one by one, and in a tube pressurised to
// 17 kPa the buffer had lost a third of them after 60 ms and the fluid next to the disc was at 3-5 kPa;
// docs/validation.md.) Serial, in column order: the new particles' order and ids do not depend on threads.
// n: the particles before this step's creations; action: what update's pass does with each of them.
void OpenBoundaries::refill_columns(Particles& P, std::size_t k, std::size_t n,
                                    const std::vector<uint8_t>& action, std::size_t& created, bool& rebuild) {
  const Zone& z = zones_[k];
  const std::size_t nc = z.columns.size();
  // The buffer's particles by column, each column front (nearest the disc) first.
  struct Member {
    int c;
    double a;
    uint32_t i;
  };
  std::vector<Member> members;
  for (std::size_t i = 0; i < n; ++i) {
    if (P.kind[i] != Kind::Inflow || (action[i] != kNone && action[i] != kFluidToInflow) || departed(P, i))
      continue;
    if (const int c = column_of(z, P.x[i]); c >= 0)
      members.push_back({c, z.axial(P.x[i]), static_cast<uint32_t>(i)});
  }
  std::sort(members.begin(), members.end(), [](const Member& p, const Member& q) {
    return p.c < q.c || (p.c == q.c && (p.a > q.a || (p.a == q.a && p.i < q.i)));
  });
  // The fluid next to the disc, for the room test of a particle added at a column's front.
  std::vector<Vec3> near_disc;
  bool near_disc_ready = false;
  auto room_in_front = [&](const Vec3& x) {
    if (!near_disc_ready) {
      for (std::size_t i = 0; i < n; ++i)
        if (P.kind[i] == Kind::Fluid && action[i] == kNone && z.axial(P.x[i]) < 2.0 * dx_ &&
            z.radial(P.x[i]) < z.spec.radius + dx_)
          near_disc.push_back(P.x[i]);
      near_disc_ready = true;
    }
    for (const Vec3& q : near_disc)
      if ((q - x).squaredNorm() < kFrontRoom * kFrontRoom * dx_ * dx_) return false;
    return true;
  };
  std::vector<std::pair<double, uint32_t>> list;  // one column's (axial position, index)
  std::size_t next = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    list.clear();
    for (; next < members.size() && members[next].c == static_cast<int>(c); ++next)
      list.push_back({members[next].a, members[next].i});
    while (static_cast<int>(list.size()) < z.spec.layers) {
      // Where the new particle goes (axial position) and whose state it copies (an index in list).
      double a = 0.0;
      std::size_t from = 0, at = list.size();  // at: its place in list
      bool found = false, behind_fluid = false;
      if (!list.empty() && list.back().first - dx_ >= -z.depth - kFarSlack * dx_) {
        a = list.back().first - dx_, from = list.size() - 1, found = true;  // behind the rear
      } else {
        double widest = 1.5 * dx_;  // the widest gap of the column, if wide enough for a particle
        for (std::size_t m = 0; m + 1 < list.size(); ++m)
          if (const double g = list[m].first - list[m + 1].first; g >= widest)
            widest = g, a = 0.5 * (list[m].first + list[m + 1].first), from = m, at = m + 1, found = true;
        if (!found) {  // in front of the front (an empty column: half a spacing behind the disc)
          a = list.empty() ? -0.5 * dx_ : list.front().first + dx_;
          from = 0, at = 0, behind_fluid = true;
          found = a <= -0.25 * dx_ && room_in_front(z.columns[c] + a * z.spec.normal);
        }
      }
      if (!found) break;
      const Vec3 x = z.columns[c] + a * z.spec.normal;
      const std::optional<std::size_t> src = list.empty() ? std::nullopt : std::optional(list[from].second);
      const std::size_t j = append_buffer_particle(P, x, Kind::Inflow, src);
      if (!src) {  // an empty column: at rest, at the background pressure
        P.rho[j] = fluid_[z.material].rho0;
        P.p[j] = fluid_[z.material].p_background;
      }
      P.m[j] = P.rho[j] * dx_ * dx_ * dx_;  // impose() sets density, pressure and mass for the step
      P.body[j] = static_cast<uint16_t>(z.spec.body);
      P.material[j] = static_cast<uint16_t>(z.material);
      ++created;
      // Far-face particles of a deep buffer wait for the next list build; any other is within the fluid's
      // reach.
      if (behind_fluid || a > -z.depth + dx_ || !defers(z)) rebuild = true;
      list.insert(list.begin() + static_cast<std::ptrdiff_t>(at), {a, static_cast<uint32_t>(j)});
    }
  }
}

// Outflow velocity, zero gradient along the axis: every outflow particle takes the normal velocity of the
// fluid at the point of the disc it lies behind, x - a n (a: its distance from the disc), the Shepard
// average of the fluid particles within a kernel support of that point (the mirror-point extrapolation of
// Tafuni, Domínguez, Vacondio & Crespo 2018, Comput. Methods Appl. Mech. Eng. 342:604, to zeroth order and
// taken at the disc). A column of the buffer thus moves as one: it neither bunches up nor stretches. Until
// stop 48 each particle averaged its fluid neighbours and the buffer particles nearer the disc, layer by
// layer, which smeared the disc's profile more at every layer; where the flow came back in through part of
// the aortic outlet and left through the rest (a valve cycle's diastole), the columns moved at different
// speeds at the disc and at the far face, and the backflow's replacements at the far face filled every
// stretch (with the swing feeding that the column count in update() stops: 1,582 particles at 0.40 s,
// 2,126 at 0.74 s; blood pushed through the aortic wall; docs/validation.md, stops 47-48). Only the normal
// component: buffer particles feel no wall and must not drift sideways. Kept as it is where no fluid is
// within a support of that point. Sums in a fixed order (cell, then index): the result does not depend on
// threads.
void OpenBoundaries::carry_disc_velocity(Particles& P, const CubicSpline& K, std::size_t n) const {
  const double h = support_;
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    if (z.spec.type != OpenBoundaryType::Outflow) continue;
    // The fluid within a support of the disc, by lateral cell (a support wide), and the buffer's particles.
    const int nr = static_cast<int>(std::ceil((z.spec.radius + 2.0 * h) / h));
    auto cell = [&](const Vec3& x, int du, int dv) {
      const auto [cu, cv] = z.cell(x, h);
      return (static_cast<int64_t>(cv) + dv + nr) * (2 * nr + 2) + (static_cast<int64_t>(cu) + du + nr);
    };
    std::vector<std::pair<int64_t, uint32_t>> near;
    std::vector<uint32_t> buffer;
    for (std::size_t i = 0; i < n; ++i) {
      if (P.kind[i] == Kind::Fluid) {
        if (std::abs(z.axial(P.x[i])) < h && z.radial(P.x[i]) < z.spec.radius + h)
          near.push_back({cell(P.x[i], 0, 0), static_cast<uint32_t>(i)});
      } else if (P.kind[i] == Kind::Outflow && !departed(P, i) &&
                 zone_of(P.x[i], Kind::Outflow) == static_cast<int>(k)) {
        buffer.push_back(static_cast<uint32_t>(i));
      }
    }
    std::sort(near.begin(), near.end());
    const Vec3 nrm = z.spec.normal;
    parallel_for(buffer.size(), [&](std::size_t b) {
      const uint32_t i = buffer[b];
      const Vec3 q = P.x[i] - z.axial(P.x[i]) * nrm;  // the point of the disc behind it
      double sw = 0.0, sv = 0.0;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          const int64_t c = cell(q, du, dv);
          auto it = std::lower_bound(near.begin(), near.end(), std::pair<int64_t, uint32_t>{c, 0});
          for (; it != near.end() && it->first == c; ++it) {
            const uint32_t j = it->second;
            const double r = (q - P.x[j]).norm();
            if (r >= h) continue;
            const double w = K.W(r) * P.m[j] / P.rho[j];
            sw += w;
            sv += w * P.v[j].dot(nrm);
          }
        }
      if (sw > 0.0) P.v[i] = (sv / sw) * nrm;
    });
  }
}

int OpenBoundaries::column_of(const Zone& z, const Vec3& x) const {
  const auto [i, j] = z.cell(x, dx_);
  if (i < -z.column_nr || i >= z.column_nr || j < -z.column_nr || j >= z.column_nr) return -1;
  return z.column_index[static_cast<std::size_t>((j + z.column_nr) * 2 * z.column_nr + (i + z.column_nr))];
}

OpenBoundaryChange OpenBoundaries::update(Particles& P, const NeighborSearch& nb, const CubicSpline& K,
                                          const Vec3& gravity, double t_new, double dt) {
  if (zones_.empty()) return {};
  const std::size_t n = P.size();

  // A step that starts at a probe row's time (a multiple of time.probe_interval) starts a new averaging
  // interval of the boundaries' flows.
  if (row_interval_ > 0.0) {
    const double t_old = t_new - dt;
    const double k = std::round(t_old / row_interval_);
    if (std::abs(t_old - k * row_interval_) <= 1e-6 * dt && k * row_interval_ > interval_start_) {
      interval_start_ = k * row_interval_;
      for (OpenBoundaryFlow& f : flows_) f.interval_volume = 0.0;
    }
  }

  carry_disc_velocity(P, K, n);

  // Pressure inlets' velocity, zero gradient along the axis: in order of increasing distance from the disc,
  // each buffer particle takes the Shepard average of its fluid neighbours and of the buffer neighbours
  // nearer the disc (already updated), so the fluid's velocity at the disc carries through the whole buffer;
  // kept as it is where no such neighbour is near. Serial, in a fixed order (distance, then index): a few
  // layers of particles only. (Outflows until stop 48 too: carry_disc_velocity.)
  const auto& idx = nb.index();
  struct Item {
    double axial;
    uint32_t i;
    int zone;
    bool operator<(const Item& o) const { return axial < o.axial || (axial == o.axial && i < o.i); }
  };
  std::vector<Item> order;
  for (std::size_t i = 0; i < n; ++i)
    if (departed(P, i)) {
      continue;
    } else if (P.kind[i] == Kind::Inflow) {
      if (const int k = zone_of(P.x[i], Kind::Inflow); k >= 0 && zones_[k].spec.pressure_inlet)
        order.push_back({-zones_[k].axial(P.x[i]), static_cast<uint32_t>(i), k});
    }
  std::sort(order.begin(), order.end());
  std::vector<int32_t> rank(order.empty() ? 0 : n, -1);
  for (std::size_t r = 0; r < order.size(); ++r) rank[order[r].i] = static_cast<int32_t>(r);
  for (std::size_t r = 0; r < order.size(); ++r) {
    const uint32_t i = order[r].i;
    double sw = 0.0;
    Vec3 sv = Vec3::Zero();
    for (uint32_t k = nb.begin(i); k < nb.end(i); ++k) {
      const uint32_t j = idx[k];
      if (P.kind[j] != Kind::Fluid && !(P.kind[j] == Kind::Inflow && rank[j] >= 0 && rank[j] < rank[i]))
        continue;
      const double W = K.W((P.x[i] - P.x[j]).norm()) * P.m[j] / P.rho[j];
      sw += W;
      sv += W * P.v[j];
    }
    // Only the normal component: the flow leaves along the outlet's axis, and buffer particles, which feel no
    // wall, must not drift out of the buffer sideways.
    const Vec3& nrm = zones_[order[r].zone].spec.normal;
    if (sw > 0.0) P.v[i] = (sv.dot(nrm) / sw) * nrm;
  }

  // Buffers move: inflow with the prescribed velocity at t_new, outflow with its own (symplectic Euler as the
  // fluid: x(t + dt) = x + dt v(t + dt)).
  std::vector<uint8_t> action(n, kNone);
  std::vector<int> zone(n, -1);  // inflow particles: their zone
  parallel_for(n, [&](std::size_t i) {
    const Kind kind = P.kind[i];
    if (departed(P, i)) return;  // waits, at rest and without mass, for the next list build
    if (kind == Kind::Inflow) {
      const int k = zone_of(P.x[i], Kind::Inflow);
      zone[i] = k;
      if (k < 0) {  // cannot happen: buffer particles move along their column
        action[i] = kInflowToFluid;
        return;
      }
      const Zone& z = zones_[k];
      if (z.spec.pressure_inlet) {
        // Moves with its own (carried) velocity; becomes fluid across the disc, leaves past the far face.
        P.v_wall[i] = P.v[i];
        P.a[i] = Vec3::Zero();
        P.x[i] += dt * P.v[i];
        const double a = z.axial(P.x[i]);
        if (a >= 0.0)
          action[i] = kInflowToFluid;
        else if (z.radial(P.x[i]) > z.spec.radius + 0.5 * dx_)
          action[i] = kRemove;
        else if (a < -z.depth - kFarSlack * dx_)
          action[i] = defers(z) ? kDepart : kRemove;
        return;
      }
      double speed = z.inflow_speed(P.x[i], t_new);
      if (z.spec.non_reflecting_tau > 0.0) {  // the outgoing wave's velocity, u' = -p_w / (rho0 c0)
        const FluidParams& fp = fluid_[z.material];
        speed = std::max(speed - flows_[k].wave_p / (fp.rho0 * fp.c0), 0.0);
      }
      P.v[i] = speed * z.spec.normal;
      P.v_wall[i] = P.v[i];
      P.a[i] = Vec3::Zero();
      P.x[i] += dt * P.v[i];
      if (z.axial(P.x[i]) >= 0.0) action[i] = kInflowToFluid;
    } else if (kind == Kind::Outflow) {
      const int k0 = zone_of(P.x[i], Kind::Outflow);
      P.v_wall[i] = P.v[i];
      P.a[i] = Vec3::Zero();
      P.x[i] += dt * P.v[i];
      if (k0 >= 0 && zones_[k0].axial(P.x[i]) > zones_[k0].depth &&
          zones_[k0].radial(P.x[i]) <= zones_[k0].spec.radius + 0.5 * dx_) {
        action[i] = defers(zones_[k0]) ? kDepart : kRemove;  // beyond the far face
        return;
      }
      const int k = zone_of(P.x[i], Kind::Outflow);
      zone[i] = k;
      if (k < 0) {
        action[i] = kRemove;  // left its buffer sideways or beyond the far face
        return;
      }
      const double a = zones_[k].axial(P.x[i]);
      if (a > zones_[k].depth)
        action[i] = kRemove;
      else if (a < 0.0)
        action[i] = kOutflowToFluid;
    } else if (kind == Kind::Fluid) {
      // Out to the wall's first layer (half a spacing beyond the disc's radius), as at the far face and at a
      // pressure inlet: fluid by the wall left as fluid inside the buffer, held only by the buffer's imposed
      // particles and the wall, was pushed into the wall just past the aortic outlet (stop 43).
      if (const int k = zone_of(P.x[i], Kind::Outflow);
          k >= 0 && zones_[k].axial(P.x[i]) >= 0.0 &&
          zones_[k].radial(P.x[i]) <= zones_[k].spec.radius + 0.5 * dx_)
        action[i] = kFluidToOutflow;
      // Fluid pushed back into an inflow buffer (a closed or slow inlet with the column sloshing) is removed
      // only once it is more than a spacing deep, past the buffer's first layer: small back-and-forth motion
      // across the disc must not drain the column.
      else if (const int m = zone_of(P.x[i], Kind::Inflow); m >= 0) {
        const Zone& z = zones_[m];
        if (z.spec.pressure_inlet) {
          // Backflow through a pressure inlet: the fluid joins the buffer at once (as at an outlet), in the
          // column its lateral position falls in (refill_columns counts it there).
          // Out to the wall's first layer (half a spacing beyond the disc's radius): fluid by the wall must
          // not run down between the buffer's outer columns and the wall.
          if (z.axial(P.x[i]) < 0.0 && z.radial(P.x[i]) <= z.spec.radius + 0.5 * dx_) {
            action[i] = kFluidToInflow;
            zone[i] = m;
          }
        } else if (z.axial(P.x[i]) < -dx_ && z.radial(P.x[i]) < z.spec.radius) {
          action[i] = kRemoveBackflow;
        }
      }
    }
  });

  // Outflow particles that stay in their buffer, by zone, and how many of them each lattice column (a
  // spacing-wide cell of the disc's (u, v) frame) holds: a particle coming back through an outlet is
  // replaced at the buffer's far face only where its column holds fewer than `layers` particles and no
  // resident particle is within half a spacing (below). Where the buffer's particles did not move back with
  // it (an outlet at rest, its column jittering across the disc), a replacement would stack on a particle
  // already there, one more at every swing: in a valve cycle's diastole that piled 14,000 extra particles
  // into the aortic outlet in 30 ms. The half-spacing room alone still let fluid that swung out into the
  // buffer (joining it) and back (replaced) add a particle per swing wherever the far face had a
  // half-spacing gap: in late diastole the aortic outlet's buffer grew from 1,582 particles to 2,126 and fed
  // the aorta blood packed tighter than its density (docs/validation.md, stops 47-48). The column count
  // keeps the buffer at its lattice's number of particles.
  // (Pressure inlets keep their buffer full column by column instead: refill_columns below.)
  std::vector<std::vector<Vec3>> resident(zones_.size());
  std::vector<std::map<std::pair<int, int>, int>> column_count(zones_.size());
  auto lateral_cell = [&](int k, const Vec3& x) { return zones_[k].cell(x, dx_); };
  if (std::find(action.begin(), action.end(), kOutflowToFluid) != action.end()) {
    for (std::size_t m = 0; m < n; ++m)
      if (action[m] == kNone && zone[m] >= 0 && P.kind[m] == Kind::Outflow) {
        resident[zone[m]].push_back(P.x[m]);
        ++column_count[zone[m]][lateral_cell(zone[m], P.x[m])];
      } else if (action[m] == kFluidToOutflow) {
        const int k = zone_of(P.x[m], Kind::Outflow);
        resident[k].push_back(P.x[m]);
        ++column_count[k][lateral_cell(k, P.x[m])];
      }
  }
  auto has_room = [&](int k, const Vec3& x) {
    if (column_count[k][lateral_cell(k, x)] >= zones_[k].spec.layers) return false;
    for (const Vec3& q : resident[k])
      if ((q - x).squaredNorm() < 0.25 * dx_ * dx_) return false;
    return true;
  };

  // One serial pass in index order: the sums, the new particles' order and ids do not depend on threads.
  std::size_t removed = 0, created = 0;
  bool rebuild = false;
  for (std::size_t i = 0; i < n; ++i) {
    switch (action[i]) {
      case kNone:
        break;
      case kInflowToFluid:
      case kOutflowToFluid: {
        P.kind[i] = Kind::Fluid;
        state_.volume_in += P.m[i] / P.rho[i];
        state_.mass_in += P.m[i];
        const int k = zone[i];
        if (k < 0) break;
        // The new buffer particle, `layers` spacings behind along the flow: behind the inlet disc, or at the
        // outlet buffer's far face when fluid flows back in through an outlet (the buffer stays full; without
        // this, every back-and-forth swing would lose the particles that passed the far face).
        const Zone& z = zones_[k];
        const bool inflow = action[i] == kInflowToFluid;
        if (inflow && z.spec.pressure_inlet) break;  // refill_columns below
        const Vec3 x_new = P.x[i] + (inflow ? -z.depth : z.depth) * z.spec.normal;
        if (!inflow) {
          if (!has_room(k, x_new)) break;
          resident[k].push_back(x_new);
          ++column_count[k][lateral_cell(k, x_new)];
        }
        append_buffer_particle(P, x_new, inflow ? Kind::Inflow : Kind::Outflow, i);
        ++created;
        if (!defers(z)) rebuild = true;
        break;
      }
      case kFluidToOutflow:
      case kFluidToInflow:  // fluid joining an outlet's or a pressure inlet's buffer leaves the domain
        P.kind[i] = action[i] == kFluidToOutflow ? Kind::Outflow : Kind::Inflow;
        P.a[i] = Vec3::Zero();
        state_.volume_out += P.m[i] / P.rho[i];
        state_.mass_out += P.m[i];
        break;
      case kRemove:
        ++removed;
        break;
      case kDepart:
        P.m[i] = 0.0;
        P.v[i] = Vec3::Zero();
        P.v_wall[i] = Vec3::Zero();
        P.a[i] = Vec3::Zero();
        break;
      case kRemoveBackflow:
        state_.volume_out += P.m[i] / P.rho[i];
        state_.mass_out += P.m[i];
        ++removed;
        break;
    }
  }
  for (std::size_t k = 0; k < zones_.size(); ++k)
    if (zones_[k].spec.pressure_inlet) refill_columns(P, k, n, action, created, rebuild);
  state_.created += created;
  state_.removed += removed;
  if (removed > 0) {
    rebuild = true;
    std::vector<uint32_t> keep;
    keep.reserve(P.size() - removed);
    for (std::size_t i = 0; i < P.size(); ++i)
      if (i >= n || (action[i] != kRemove && action[i] != kRemoveBackflow))
        keep.push_back(static_cast<uint32_t>(i));
    P.permute(keep);
  }

  // The flows of this step; the Windkessels advance with them to t_new.
  const std::vector<SlabSums> sums = slab_sums(P);
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    OpenBoundaryFlow& f = flows_[k];
    const double q = slab_flow(sums[k]);
    f.flow = q;
    f.interval_volume += q * dt;
    if (zones_[k].spec.windkessel) windkessel_step(*zones_[k].spec.windkessel, f.windkessel, q, dt);
  }
  // Non-reflecting boundaries (open_boundary.hpp): the wave parts advance over the step, pressure-driven ones
  // with the disc velocity before their pressure is imposed, velocity inlets with the slab pressure after.
  if (non_reflecting()) {
    for (std::size_t k = 0; k < zones_.size(); ++k) {
      const Zone& z = zones_[k];
      if (!(z.spec.non_reflecting_tau > 0.0) || !z.pressure_driven()) continue;
      const FluidParams& fp = fluid_[z.material];
      const double s = z.spec.type == OpenBoundaryType::Outflow ? 1.0 : -1.0;
      const double u = slab_velocity(sums[k]);
      OpenBoundaryFlow& f = flows_[k];
      f.wave_p =
          std::exp(-dt / z.spec.non_reflecting_tau) * f.wave_p + s * fp.rho0 * fp.c0 * (u - f.wave_ref);
      f.wave_ref = u;
    }
  }
  impose(P, gravity, t_new);
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    if (!(z.spec.non_reflecting_tau > 0.0) || z.pressure_driven()) continue;
    OpenBoundaryFlow& f = flows_[k];
    f.wave_p = std::exp(-dt / z.spec.non_reflecting_tau) * f.wave_p + (f.pressure - f.wave_ref);
    f.wave_ref = f.pressure;
  }
  return {created, rebuild};
}

std::vector<uint32_t> OpenBoundaries::take_departed(const Particles& P) {
  std::vector<uint32_t> keep;
  keep.reserve(P.size());
  for (std::size_t i = 0; i < P.size(); ++i)
    if (!departed(P, i)) keep.push_back(static_cast<uint32_t>(i));
  if (keep.size() == P.size()) return {};
  state_.removed += P.size() - keep.size();
  return keep;
}

}  // namespace aortasph
