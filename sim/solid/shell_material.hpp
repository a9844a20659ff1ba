// Plane-stress constitutive laws of the shell (sim/solid/shell.hpp), at one Gauss point through the
// thickness, in the particle's local frame (T1, T2, N): E is the Green-Lagrange strain, S the second
// Piola-Kirchhoff stress, psi the energy per reference volume. S33 = 0 (plane stress): the normal strain E33
// is not an unknown of the kinematics (the director is unit) but follows from S33 = 0 and is eliminated.
//   - Saint Venant-Kirchhoff in plane stress (the SPHinXsys shell's law; e.g. Bathe, "Finite Element
//     Procedures", 1996, eq. 6.41 with the Green strain): S_ab = E / (1 - nu^2) ((1 - nu) E_ab + nu E_cc
//     delta_ab), a, b in-plane; transverse shear S_a3 = kappa 2 G E_a3, kappa = 5/6 (Reissner 1945).
//   - Incompressible neo-Hookean in plane stress (Holzapfel, "Nonlinear Solid Mechanics", 2000, sect. 6.5,
//     the membrane form): lambda3^2 = 1 / det C2 with C2 the in-plane 2x2 block of C = I + 2E; psi = mu/2
//     (tr C2 + 1 / det C2 - 3), S_ab = mu (delta_ab - C2^-1_ab / det C2); mu = E / 3 (the small-strain
//     Young's modulus is E); transverse shear as above, linear in E_a3 with kappa 2 mu.
//   - Lee-Sacks, isotropic: the member delta = 1 (no fibre term) of the Lee-Sacks form W = c0/2 (I1 - 3) +
//     c1/2 (delta exp(c2 (I1 - 3)^2) + (1 - delta) exp(c3 (I4 - 1)^2) - 1), the Fung-type law Hsu et al. 2015
//     (Comput. Mech. 55:1211) used for valve leaflets (as the project's reference sheet valve-physiology.md,
//     section 4, quotes it; Lee, Sacks et al. 2014 is its origin, not re-read here), incompressible
//     in plane stress as the neo-Hookean above with c0 = mu = E / 3: psi = mu/2 x + c1/2 (exp(c2 x^2) - 1),
//     x = I1 - 3 = tr C2 + 1 / det C2 - 3; S_ab = 2 W1 (delta_ab - C2^-1_ab / det C2), W1 = dpsi/dI1 = mu/2 +
//     c1 c2 x exp(c2 x^2). Soft at small strain (E), it stiffens as collagen does: c1, c2 set where.
//   - Lee-Sacks with fibres (delta < 1): the isotropic exponential scaled by delta, and the fibre term
//     c1/2 (1 - delta) (exp(c3 y^2) - 1), y = I4 - 1, I4 = a0 . C2 a0 the squared stretch along the unit
//     fibre direction a0 of the reference tangent plane; in tension only (y > 0: collagen does not carry
//     compression; Holzapfel, Gasser & Ogden 2000 use the same switch). a0 lies in the plane, so the plane
//     stress multiplier is the isotropic one's and S_ab += 2 W4 a0_a a0_b, W4 = c1 (1 - delta) c3 y
//     exp(c3 y^2). Aortic leaflets: a0 circumferential (the collagen of the cusps runs from commissure to
//     commissure; Sacks, Merryman & Schmidt 2009, J. Biomech. 42:1804, recalled).
#pragma once

#include <Eigen/Dense>

#include "scene.hpp"

namespace aortasph {

using Mat3 = Eigen::Matrix3d;

struct ShellParams {
  double rho0 = 1000.0;
  double E = 0.0, nu = 0.0;
  double t = 0.0;       // thickness [m]
  double mu = 0.0;      // shear modulus [Pa]
  double lam_ps = 0.0;  // plane-stress lambda, E nu / (1 - nu^2)
  double kappa = 5.0 / 6.0;
  double c_plate = 0.0;  // plate (in-plane) wave speed sqrt(E / (rho0 (1 - nu^2))) [m/s]
  double damping = 0.0;  // [1/s]
  double eta = 0.0;      // Kelvin-Voigt viscosity of the in-plane strain rate [Pa s] (Shells::compute)
  double hourglass = 0.0;
  bool neo_hookean = false;
  double c1 = 0.0, c2 = 0.0;     // Lee-Sacks exponential terms (c1 = 0: none)
  double c3 = 0.0, delta = 1.0;  // the fibre term's exponent and the isotropic share (1: no fibre term)
  ShellParams() = default;
  explicit ShellParams(const Material& m);
};

// S (local frame, symmetric, S33 = 0) and psi for a local Green-Lagrange strain E (E33 ignored). With
// stiffening (Lee-Sacks only), an upper estimate of the in-plane tangent stiffness over its small-strain
// value: lambda_max^2 (2 W1 + 2 W11 |dI1/dC|^2) / mu with W11 = d2psi/dI1^2 and lambda_max^2 the largest
// eigenvalue of C2 (1 at no strain; the wave speed grows with its square root, Shells::stable_dt).
// fibre: the unit fibre direction in the local frame's plane (Lee-Sacks with delta < 1; nullptr or zero:
// none).
void shell_stress(const ShellParams& p, const Mat3& E, Mat3& S, double& psi, double* stiffening = nullptr,
                  const Eigen::Vector2d* fibre = nullptr);

}  // namespace aortasph
