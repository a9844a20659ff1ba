// Thin shells: one layer of particles on the mid-surface, the thickness a parameter (docs/model.md,
// "Shells").
//
// Kinematics (Uflyand-Mindlin / Reissner-Mindlin, the degenerated-solid form): a material point at thickness
// coordinate zeta in [-t/2, t/2] is at X + zeta N in the reference and at x + zeta d now, with d the unit
// director of the particle (not kept normal to the mid-surface: the difference is the transverse shear).
// This follows Wu, Zhang & Hu 2023, "An SPH formulation for general plate and shell structures with finite
// deformation and large rotation" (J. Comput. Phys.; arXiv 2309.02838), the thin-structure dynamics of
// SPHinXsys, with these choices of our own:
//   - the director is a unit vector advanced by its angular velocity (d <- R(omega dt) d), not two angles;
//   - the deformation gradient is computed from positions and directors (total Lagrangian), not time
//     integrated: for particle i, with the in-plane corrected gradient weights g_ij (a 2-vector in i's
//     reference tangent frame; the 2-D kernel-gradient correction, Wu et al. sect. 2.3, Bonet & Lok 1999),
//       G_i = sum_j A_j (x_j - x_i) (x) g_ij       (the mid-surface tangents dx/dxi, 3x2)
//       H_i = sum_j A_j (d_j - d_i) (x) g_ij       (the director gradient, 3x2)
//     and at a Gauss point zeta the 3-D gradient F = [G + zeta H | d] [G0 + zeta H0 | N]^-1 (G0, H0: the
//     same sums in the reference), which is exactly a rotation for every rigid motion (zero stress);
//   - plane stress at every Gauss point: the plane-stress Saint Venant-Kirchhoff matrix or the incompressible
//     neo-Hookean law with lambda3 = 1 / (lambda1 lambda2) (sim/solid/shell_material.hpp), transverse shear
//     with the 5/6 correction;
//   - the internal forces and director moments are the exact derivatives of the elastic energy
//     U = sum_i sum_k A_i w_k psi(E_k) (2-point Gauss rule through the thickness for SVK, 3 for neo-Hookean):
//     the nominal resultants dU/dG_i (membrane), dU/dH_i (moment) and dU/dd_i (transverse shear) contracted
//     with the gradient weights. So the internal forces conserve linear and angular momentum (U is invariant
//     under translation and rotation) and, undamped, energy;
//   - hourglass control is an energy too (as in sim/solid/solid_tlsph.cpp): U_hg = sum over pairs
//     1/2 k_ij |eps_ij|^2 with eps_ij = (F_i + F_j) X_ij / 2 - x_ij, zero for every affine motion and third
//     order for smooth ones, against the zig-zag modes that nodal integration cannot see; the part of eps
//     along the pair's mean director is weighted by beta = min(1, 3 t^2 / |X_ij|^2), the bending scale (at
//     the membrane's it locks thin sheets in bending; Shells::update, docs/validation.md "Shells");
//   - the in-plane Green-Lagrange strain is corrected for the linear weights' third-order error on a curved
//     sheet (the stencil's third moments times the change of Q(B) = B B, B = -sym(G^T H) the curvature;
//     Shells::update, docs/model.md "Shells"): without it a cylinder bent without stretching stored 4.3x its
//     bending energy at Delta x / t = 9.8 (membrane locking); saturated smoothly at 1 % of strain where a
//     sheet folds within a few spacings and the series no longer holds;
//   - rotary inertia rho t^3 / 12 per area; mass rho t per area.
// Neighbours are the reference neighbours of one body (found once); shells do not see the fluid yet.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/kernel.hpp"
#include "core/particles.hpp"
#include "core/periodic.hpp"
#include "core/slot_map.hpp"
#include "solid/shell_material.hpp"

namespace aortasph {

// What the World hands over per shell particle at t = 0 (indexed like Particles).
struct ShellSeed {
  Vec3 normal = Vec3::UnitZ();
  double area = 0.0;
  uint8_t support = 0;  // 0 free, 1 fixed (position and rotation), 2 pinned (position only)
  // Fibre direction (Lee-Sacks with fibres), projected on the tangent plane by Shells; zero: none.
  Vec3 fibre = Vec3::Zero();
};

class Shells {
 public:
  using Mat32 = Eigen::Matrix<double, 3, 2>;
  using Mat2 = Eigen::Matrix2d;

  Shells() = default;
  // Reference configuration of every Kind::Shell particle of P; seed is indexed like P. Along periodic axes
  // (per) a sheet continues through the domain's faces: neighbours and every pair separation, in the
  // reference and now, are nearest images (a plate strip periodic across its width is in cylindrical
  // bending, the plane-strain plate of quasi-2-D benchmarks).
  Shells(const Particles& P, const std::vector<Material>& materials, const CubicSpline& kernel,
         const std::vector<ShellSeed>& seed, const Periodic& per = Periodic());

  std::size_t size() const { return X_.size(); }
  bool empty() const { return X_.empty(); }
  void reindex(const Particles& P);

  // Resultants, energy, forces and director moments from the current positions and directors; adds the
  // internal forces to f (indexed like P). v: the shells' velocities by slot, for a material with a
  // `dynamic_viscosity` (its Kelvin-Voigt stress needs the strain rate; the directors' rate is omega x d);
  // nullptr, or no viscous material: elastic forces only.
  void update(const Particles& P, const std::vector<Vec3>* v = nullptr);
  // Checkpoint: the positions (by slot) and directors the last update() computed from, and that update
  // again from them (a resumed run then reads the same normals, stresses and forces before its first
  // update as the saved run did: they lag the positions by the last sub-step's drift).
  const std::vector<Vec3>& update_positions() const { return x_; }
  const std::vector<Vec3>& update_directors() const { return d_update_; }
  void restore_update(std::vector<Vec3> x, std::vector<Vec3> d);
  void add_forces(std::vector<Vec3>& f) const;
  // Director update: omega += kick (tau / I - c omega), d <- R(omega dt) d. Supports hold their director.
  void advance_directors(double dt, double kick);

  // Largest stable step: cfl min(h / (c_plate + v), the shear-rotary limit) (Wu et al., SPHinXsys
  // ShellAcousticTimeStepSize term 5).
  double stable_dt(double cfl, double max_speed) const;

  uint32_t at(std::size_t s) const { return at_[s]; }
  long slot(std::size_t i) const {
    return i < slot_.size() && slot_[i] != kNone ? static_cast<long>(slot_[i]) : -1;
  }
  double mass(std::size_t s) const { return mass_[s]; }
  double area(std::size_t s) const { return area_[s]; }
  double damping(std::size_t s) const { return params_[material_[s]].damping; }
  uint8_t support(std::size_t s) const { return support_[s]; }
  const Vec3& reference(std::size_t s) const { return X_[s]; }
  const Vec3& reference_normal(std::size_t s) const { return N_[s]; }
  // The fibre direction in the reference (unit, in the tangent plane; zero where the sheet has none).
  Vec3 fibre(std::size_t s) const { return fibre_[s](0) * T1_[s] + fibre_[s](1) * T2_[s]; }
  const Vec3& director(std::size_t s) const { return d_[s]; }
  const Vec3& omega(std::size_t s) const { return omega_[s]; }
  double thickness(std::size_t s) const { return params_[material_[s]].t; }
  double rotary_inertia(std::size_t s) const { return inertia_[s]; }
  // Current mid-surface normal (G column 0 x column 1, normalised; oriented like N), as of the last update;
  // the director where the tangents vanish. Kept by compute() (the fluid coupling reads it for every triangle
  // near a fluid particle, several times per sub-step).
  Vec3 normal(std::size_t s) const { return has_normal_[s] ? normal_[s] : d_[s]; }
  // Whether the point x_s + r (r from the particle's position at the last update()) lies over its sheet:
  // within `reach` of the particle or of one of its reference neighbours, where they are now. Inside a
  // sheet every nearby point does (true at once); near an edge (the two or three rows whose reference
  // neighbourhood's first moment, sum_t W (X_t - X_s) / sum_t W, exceeds 0.08 of the neighbours' mean
  // distance, about 0.1 dx: the fluid coupling's test) a point beyond the edge does not.
  bool near_edge(std::size_t s) const { return edge_[s] != 0; }
  bool over_sheet(std::size_t s, const Vec3& r, double reach) const {
    if (!edge_[s]) return true;
    const double r2 = reach * reach;
    if (r.squaredNorm() <= r2) return true;
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k)
      if ((sep(x_[nbr_[k]], x_[s]) - r).squaredNorm() <= r2) return true;
    return false;
  }
  // Of the particle s and its reference neighbours, the one (slot) whose position at the last update() lies
  // nearest to the point x_s + r, and its offset from x_s: the patch of the sheet that point faces.
  std::pair<std::size_t, Vec3> nearest_patch(std::size_t s, const Vec3& r) const {
    std::pair<std::size_t, Vec3> best{s, Vec3::Zero()};
    double d2 = r.squaredNorm();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const Vec3 o = sep(x_[nbr_[k]], x_[s]);
      const double e2 = (r - o).squaredNorm();
      if (e2 < d2) {
        d2 = e2;
        best = {nbr_[k], o};
      }
    }
    return best;
  }
  const Vec3& torque(std::size_t s) const { return torque_[s]; }
  // Internal force of the last update() on slot s [N] (what add_forces() adds).
  const Vec3& internal_force(std::size_t s) const { return force_[s]; }
  double von_mises(std::size_t s) const { return vm_[s]; }
  // Largest principal in-plane Green-Lagrange strain of the last update() over the particle's Gauss points
  // through the thickness (the surfaces carry the bending strain).
  double strain(std::size_t s) const { return strain_[s]; }
  // Resultants per unit reference length in the particle's reference tangent frame (T1, T2, N):
  // membrane force N [N/m], moment M [N m / m], transverse shear force Q [N/m] (PK2 through the thickness).
  const Mat2& membrane(std::size_t s) const { return Nres_[s]; }
  const Mat2& moment(std::size_t s) const { return Mres_[s]; }
  const Eigen::Vector2d& shear(std::size_t s) const { return Qres_[s]; }
  const Vec3& tangent(std::size_t s, int k) const { return k == 0 ? T1_[s] : T2_[s]; }
  // Elastic energy plus the hourglass energy of the last update() [J].
  double energy() const;
  // Kinetic energy of the directors' spin, sum I |omega|^2 / 2 [J].
  double rotational_energy() const;

  // Checkpoint: the directors and their angular velocities, by shell slot.
  std::vector<Vec3>& directors() { return d_; }
  std::vector<Vec3>& omegas() { return omega_; }
  const std::vector<Vec3>& directors() const { return d_; }
  const std::vector<Vec3>& omegas() const { return omega_; }
  // The stiffening of each slot at the last update() (stable_dt's, 1 unless a Lee-Sacks law stiffened),
  // saved so that a resumed run takes the steps the uninterrupted one took; whether any material stiffens.
  std::vector<double>& stiffening() { return stiffening_; }
  const std::vector<double>& stiffening() const { return stiffening_; }
  bool stiffens() const { return stiffens_; }

  // For tests and validations: set the current director of slot s; an external moment on slot s [N m] (held
  // until changed); a support of slot s (0 free, 1 fixed, 2 pinned, 3 a diaphragm: the position held in the
  // plane perpendicular to axis, free along it, the director free; 4 the same with the director's rotation
  // about axis held too, the "hard" simple support of a Mindlin shell).
  void set_director(std::size_t s, const Vec3& d) { d_[s] = d.normalized(); }
  void set_external_moment(std::size_t s, const Vec3& m) {
    if (external_.empty()) external_.assign(X_.size(), Vec3::Zero());
    external_[s] = m;
  }
  void set_support(std::size_t s, uint8_t support, const Vec3& axis = Vec3::UnitX()) {
    support_[s] = support;
    if (support == 3 || support == 4) {
      if (free_axis_.empty()) free_axis_.assign(X_.size(), Vec3::Zero());
      free_axis_[s] = axis.normalized();
    }
  }
  // Diaphragm supports: the direction left free.
  const Vec3& free_axis(std::size_t s) const { return free_axis_[s]; }

 private:
  static constexpr uint32_t kNone = kSlotNone;
  static constexpr int kGauss = 3;
  std::vector<ShellParams> params_;  // per material
  double h_ = 0.0;
  Periodic per_;
  // x_t - x_s, or its nearest image along periodic axes.
  Vec3 sep(const Vec3& xt, const Vec3& xs) const { return per_.any ? per_.image(xt - xs) : Vec3(xt - xs); }
  // Reference, per shell slot.
  std::vector<uint32_t> id_;
  std::vector<Vec3> X_, N_, T1_, T2_;
  std::vector<Eigen::Vector2d> fibre_;  // unit fibre direction in (T1, T2); zero: none
  std::vector<double> area_, mass_, inertia_;
  std::vector<uint8_t> edge_;  // 1 for a particle near an edge of its sheet (over_sheet)
  std::vector<uint16_t> material_;
  std::vector<uint8_t> support_;
  // Per Gauss point k of slot s (index 3 s + k): J0^-1 and the reference volume A w_k det(J0_k) / det(J0_0).
  std::vector<Mat3> K0_;
  std::vector<double> vol_;
  // Reference neighbours (CSR), per pair: corrected weight g_ij, the reverse pair's index, b_ij = K0_i X_ij
  // (at mid-surface), hourglass stiffness.
  std::vector<uint32_t> offset_, nbr_, rev_;
  std::vector<Eigen::Vector2d> g_;
  std::vector<Vec3> b_;
  std::vector<double> k_hg_;
  // The membrane strain's curvature correction (Shells::update): per slot the stencil's third moments
  // m3[a][b][c][l] = sum_t A_t a_a a_b a_c g_l (index 8 a + 4 b + 2 c + l) and Q(B0) of the reference
  // curvature B0 = -sym(G0^T H0).
  std::vector<std::array<double, 16>> m3_;
  std::vector<Mat2> q3ref_;
  // Index maps.
  std::vector<uint32_t> at_, slot_, s_of_id_;
  // State.
  std::vector<Vec3> d_, omega_;
  std::vector<Vec3> external_, free_axis_;  // empty unless set (tests, validations)
  // Per update.
  std::vector<Vec3> x_;         // positions gathered by slot
  std::vector<Vec3> d_update_;  // the directors compute() used
  void compute();               // update() from x_ and d_
  std::vector<Mat32> G_, H_, PG_, PH_;
  std::vector<Vec3> normal_;         // G column 0 x column 1, normalised
  std::vector<uint8_t> has_normal_;  // 0 where that cross product vanishes
  std::vector<Vec3> q_, hg_force_, force_, torque_;
  std::vector<Mat3> F0_;
  std::vector<double> energy_, vm_, strain_;
  std::vector<double> stiffening_;  // stiffening laws: the tangent's rise over its small-strain value (>= 1)
  bool stiffens_ = false;           // a material with a stiffening law (Lee-Sacks c1 > 0)
  bool viscous_ = false;            // a material with a Kelvin-Voigt viscosity (eta > 0)
  const std::vector<Vec3>* v_ = nullptr;  // the velocities of this update() (viscous_ only), by slot
  std::vector<Mat32> Gd_, Hd_;            // their rates of G and H (viscous_ only)
  std::vector<Vec3> dd_;                  // the directors' rates omega x d (viscous_ only)
  std::vector<double> visc_lambda_;       // per material: the viscous operator's rate bound [1/m^2]
  std::vector<Mat2> Nres_, Mres_;
  std::vector<Eigen::Vector2d> Qres_;
};

}  // namespace aortasph
