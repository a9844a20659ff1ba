#include "solid/shell_material.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace aortasph {

ShellParams::ShellParams(const Material& m)
    : rho0(m.density),
      E(m.youngs_modulus),
      nu(m.neo_hookean ? 0.5 : m.poisson_ratio),
      t(m.thickness),
      mu(m.neo_hookean ? m.youngs_modulus / 3.0 : m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio))),
      lam_ps(m.neo_hookean ? 2.0 * m.youngs_modulus / 3.0
                           : m.youngs_modulus * m.poisson_ratio / (1.0 - m.poisson_ratio * m.poisson_ratio)),
      c_plate(std::sqrt(m.youngs_modulus / (m.density * (1.0 - nu * nu)))),
      damping(m.shell_damping),
      eta(m.shell_viscosity),
      hourglass(m.hourglass),
      neo_hookean(m.neo_hookean),
      c1(m.lee_sacks_c1),
      c2(m.lee_sacks_c2),
      c3(m.lee_sacks_c3),
      delta(m.lee_sacks_delta) {}

void shell_stress(const ShellParams& p, const Mat3& E, Mat3& S, double& psi, double* stiffening,
                  const Eigen::Vector2d* fibre) {
  S.setZero();
  const double ks = p.kappa * 2.0 * p.mu;  // transverse shear, S_a3 = kappa 2 mu E_a3
  S(0, 2) = S(2, 0) = ks * E(0, 2);
  S(1, 2) = S(2, 1) = ks * E(1, 2);
  psi = ks * (E(0, 2) * E(0, 2) + E(1, 2) * E(1, 2));
  if (!p.neo_hookean) {
    const double tr = E(0, 0) + E(1, 1);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) S(a, b) = 2.0 * p.mu * E(a, b) + (a == b ? p.lam_ps * tr : 0.0);
    psi +=
        0.5 * p.lam_ps * tr * tr + p.mu * (E(0, 0) * E(0, 0) + E(1, 1) * E(1, 1) + 2.0 * E(0, 1) * E(0, 1));
    return;
  }
  // Incompressible neo-Hookean, plane stress: lambda3^2 = 1 / det C2.
  Eigen::Matrix2d C = Eigen::Matrix2d::Identity() + 2.0 * E.topLeftCorner<2, 2>();
  const double det = std::max(C.determinant(), 1e-6);
  const Eigen::Matrix2d Cinv = C.inverse();
  const Eigen::Matrix2d g = Eigen::Matrix2d::Identity() - Cinv / det;  // dI1/dC (in plane)
  const double x = C.trace() + 1.0 / det - 3.0;                        // I1 - 3
  if (p.c1 <= 0.0) {
    S.topLeftCorner<2, 2>() = p.mu * g;
    psi += 0.5 * p.mu * x;
    return;
  }
  // Lee-Sacks: W1 = mu/2 + c1 delta c2 x exp(c2 x^2), S = 2 W1 g (+ the fibre's 2 W4 a0 a0^T).
  const double e = std::exp(p.c2 * x * x);
  const double W1 = 0.5 * p.mu + p.c1 * p.delta * p.c2 * x * e;
  S.topLeftCorner<2, 2>() = 2.0 * W1 * g;
  psi += 0.5 * p.mu * x + 0.5 * p.c1 * p.delta * (e - 1.0);
  double W4 = 0.0, W44 = 0.0;
  if (fibre && p.delta < 1.0 && fibre->squaredNorm() > 0.0) {
    // Tension only (y = I4 - 1 > 0). W44 is not zero at y = 0: the fibres are stiff from the first stretch,
    // and the step's bound takes it at max(y, 0), from the unstrained state on (whatever the rounding of y).
    const double y = fibre->dot(C * *fibre) - 1.0, yp = std::max(y, 0.0);
    const double c = p.c1 * (1.0 - p.delta), e4 = std::exp(p.c3 * yp * yp);
    W44 = c * p.c3 * (1.0 + 2.0 * p.c3 * yp * yp) * e4;
    if (y > 0.0) {
      W4 = c * p.c3 * y * e4;
      S.topLeftCorner<2, 2>() += 2.0 * W4 * (*fibre) * fibre->transpose();
      psi += 0.5 * c * (e4 - 1.0);
    }
  }
  if (stiffening) {
    const double W11 = p.c1 * p.delta * p.c2 * (1.0 + 2.0 * p.c2 * x * x) * e;
    // The material part (W1, W11; W4, W44 with |dI4/dC| = |a0|^2 = 1) times the geometric one: the largest
    // squared stretch in the plane.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(C, Eigen::EigenvaluesOnly);
    const double stretch2 = std::max(1.0, eig.eigenvalues().maxCoeff());
    *stiffening =
        std::max(1.0, stretch2 * (2.0 * W1 + 2.0 * W11 * g.squaredNorm() + 2.0 * W4 + 2.0 * W44) / p.mu);
  }
}

}  // namespace aortasph
