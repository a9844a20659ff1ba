// Elastic solids by Total-Lagrangian SPH, paper section 3.2, eqs. (14)-(18):
//   deformation gradient  F_i = sum_j V_j (x_j - x_i) (x) L_i grad W(X_i - X_j)        (14)
//   Green-Lagrange strain E = (F^T F - I) / 2                                          (15)
//   Saint Venant-Kirchhoff S = lambda tr(E) I + 2 mu E                                 (16) (the paper's
//                                                          printed form drops the identity after tr(E))
//   first Piola-Kirchhoff P = F S                                                      (17)
//   nodal force           f_i = sum_j V_i V_j (P_i L_i + P_j L_j) grad_i W(X_i - X_j)  (18)
// Eq. (14) is written here with x_j - x_i instead of u_j - u_i plus I: the two agree where the kernel sum is
// exact, and the form with positions is exact everywhere once the gradient is corrected. Eq. (18) is the
// derivative of the elastic energy sum_i V_i psi(F_i) with respect to x_i, so it conserves linear and angular
// momentum and, without the stabilisers below, energy.
// What makes it right and stable in practice:
//   - kernel gradient correction (Bonet & Lok 1999, Comput. Methods Appl. Mech. Engrg. 180:97, eq. 45):
//     L_i = (sum_j V_j grad_i W_ij (x) (X_j - X_i))^-1, so F is exact for every linear deformation, also at
//     free surfaces where the kernel is cut (thin leaflets are all surface);
//   - hourglass control (Ganzenmueller 2015, Comput. Methods Appl. Mech. Engrg. 286:87, eqs. 19-23): a pair
//     force against the difference between where F_i places j and where j is, which is zero for every affine
//     deformation and resists the zero-energy modes that eq. (14) cannot see;
//   - artificial viscosity (Monaghan 1992, Annu. Rev. Astron. Astrophys. 30:543, eq. 4.2) on the reference
//     neighbours, with the solid's P-wave speed, for approaching pairs only.
// Neighbours come from the reference configuration and are found once (section 3.2: "the initial particle
// configuration defines the neighborhood"); particles of different bodies are never neighbours here.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "core/kernel.hpp"
#include "core/particles.hpp"
#include "core/slot_map.hpp"

namespace aortasph {

using Mat3 = Eigen::Matrix3d;

// Per-material constants of an elastic material (read-only during a run).
struct SolidParams {
  double rho0 = 1000.0;
  double E = 0.0;       // Young's modulus [Pa]
  double nu = 0.0;      // Poisson ratio
  double lambda = 0.0;  // Lame constants [Pa]
  double mu = 0.0;
  double c = 0.0;          // P-wave speed sqrt((lambda + 2 mu) / rho0) [m/s]
  double hourglass = 0.0;  // Ganzenmueller's alpha
  double alpha = 0.0;      // artificial viscosity
  bool neo_hookean = false;
  bool second_order = true;  // gradient correction (Material::second_order_gradient)
  explicit SolidParams(const Material& m);
  SolidParams() = default;
};

// Stress and strain of one particle: S from E (eq. 16) and P = F S (eq. 17), the elastic energy density and
// the von Mises stress of the Cauchy stress sigma = P F^T / det F.
struct StressState {
  Mat3 S, P;
  double energy_density = 0.0;  // psi = lambda/2 tr(E)^2 + mu E:E [J/m^3]
  double von_mises = 0.0;       // [Pa]
};
StressState svk_stress(const Mat3& F, double lambda, double mu);
// Compressible neo-Hookean (Bonet & Wood 2008, "Nonlinear Continuum Mechanics for Finite Element Analysis",
// eqs. 6.27-6.28): psi = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2, P = mu (F - F^-T) + lambda ln J F^-T.
// The same small-strain limit as eq. (16), but its resistance grows without bound as J -> 0, where Saint
// Venant-Kirchhoff softens and lets a particle collapse (past a stretch of 1/sqrt(3) in uniaxial
// compression). J is floored at 0.01 to keep a collapsed particle finite.
StressState neo_hookean_stress(const Mat3& F, double lambda, double mu);

// All elastic particles of a world. Arrays are indexed by the solid's own index s, which does not change when
// the particles are re-sorted; at[s] is particle s's current index in Particles (refreshed by reindex()).
class Solids {
 public:
  Solids() = default;
  // Reference configuration: X = x0 of every elastic particle in P, volume dx^3, mass rho0 dx^3; clamped[i]
  // (indexed like P, may be empty) marks particles held at X. Builds the reference neighbour lists and the
  // corrected gradients once.
  Solids(const Particles& P, const std::vector<Material>& materials, const CubicSpline& kernel, double dx,
         const std::vector<uint8_t>& clamped);

  std::size_t size() const { return X_.size(); }
  bool empty() const { return X_.empty(); }
  // After the particles were permuted (sorted, removed): finds each solid particle again by its id. Throws
  // InstabilityError when one is gone (an elastic particle that left the domain breaks its body).
  void reindex(const Particles& P);

  // eqs. (14)-(17) for every solid particle from the current positions.
  void update_stress(const Particles& P);
  // Adds to f (indexed like P) the internal forces (eq. 18), hourglass control and artificial viscosity.
  void add_forces(const Particles& P, std::vector<Vec3>& f) const;

  // Largest P-wave speed over the materials present [m/s].
  double max_wave_speed() const { return max_c_; }
  // Smallest particle mass [kg] (contact time step).
  double min_mass() const { return min_mass_; }

  // Per solid particle s.
  uint32_t at(std::size_t s) const { return at_[s]; }
  double mass(std::size_t s) const { return mass_[s]; }
  bool clamped(std::size_t s) const { return clamped_[s] != 0; }
  const Vec3& reference(std::size_t s) const { return X_[s]; }
  const Mat3& F(std::size_t s) const { return F_[s]; }
  const Mat3& PK1(std::size_t s) const { return P_[s]; }
  double von_mises(std::size_t s) const { return vm_[s]; }
  // Solid index of particle i, or -1 when i is not elastic.
  long slot(std::size_t i) const { return slot_[i] == kNone ? -1 : static_cast<long>(slot_[i]); }
  // Elastic energy sum_s V_s psi(F_s) of the current positions plus the hourglass springs' energy [J].
  double elastic_energy(const Particles& P) const;
  std::size_t reference_pairs() const { return nbr_.size(); }

 private:
  static constexpr uint32_t kNone = kSlotNone;
  const CubicSpline* kernel_ = nullptr;
  std::vector<SolidParams> params_;  // per material
  double max_c_ = 0.0, min_mass_ = 0.0;
  // Reference state, per solid particle.
  std::vector<uint32_t> id_;  // particle id
  std::vector<Vec3> X_;
  std::vector<double> volume_, mass_;
  std::vector<uint16_t> material_;
  std::vector<uint8_t> clamped_;
  // Reference neighbours (CSR over s) and, per pair, the corrected gradients g_ij = L_i grad_i W(X_i - X_j)
  // and g_ji = L_j grad_j W(X_j - X_i), so that the force loop gathers without touching j's list.
  std::vector<uint32_t> offset_, nbr_;
  std::vector<Vec3> g_ij_, g_ji_;
  std::vector<double> w_ij_;  // W(|X_ij|), for hourglass control
  // Index maps.
  std::vector<uint32_t> at_;       // s -> particle index
  std::vector<uint32_t> slot_;     // particle index -> s
  std::vector<uint32_t> s_of_id_;  // particle id -> s
  // State of the step.
  std::vector<Mat3> F_, P_;
  // P_ plus the hourglass springs' energy differentiated by F (Q_s / V_s, see update_stress()): what the
  // force loop of eq. (18) uses. Per pair (s's list), the springs' pair term on s, subtracted from its force.
  std::vector<Mat3> P_force_;
  std::vector<Vec3> hourglass_pair_;
  std::vector<double> vm_;
  Mat3 deformation_gradient(const Particles& P, std::size_t s) const;
};

}  // namespace aortasph
