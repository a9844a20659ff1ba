#include "solid/solid_tlsph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "core/neighbors.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "core/slot_map.hpp"

namespace aortasph {

SolidParams::SolidParams(const Material& m)
    : rho0(m.density),
      E(m.youngs_modulus),
      nu(m.poisson_ratio),
      lambda(m.youngs_modulus * m.poisson_ratio / ((1.0 + m.poisson_ratio) * (1.0 - 2.0 * m.poisson_ratio))),
      mu(m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio))),
      c(std::sqrt((lambda + 2.0 * mu) / m.density)),
      hourglass(m.hourglass),
      alpha(m.solid_art_viscosity),
      neo_hookean(m.neo_hookean),
      second_order(m.second_order_gradient) {}

namespace {

// Von Mises equivalent of a Cauchy stress.
double von_mises_of(const Mat3& sig) {
  const double d01 = sig(0, 0) - sig(1, 1), d12 = sig(1, 1) - sig(2, 2), d20 = sig(2, 2) - sig(0, 0);
  const double shear = sig(0, 1) * sig(0, 1) + sig(1, 2) * sig(1, 2) + sig(2, 0) * sig(2, 0);
  return std::sqrt(0.5 * (d01 * d01 + d12 * d12 + d20 * d20) + 3.0 * shear);
}

}  // namespace

StressState svk_stress(const Mat3& F, double lambda, double mu) {
  StressState s;
  // eq. (15)
  const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
  const double trE = E.trace();
  // eq. (16), with the identity
  s.S = lambda * trE * Mat3::Identity() + 2.0 * mu * E;
  // eq. (17)
  s.P = F * s.S;
  s.energy_density = 0.5 * lambda * trE * trE + mu * E.cwiseProduct(E).sum();
  // Cauchy stress sigma = J^-1 P F^T = J^-1 F S F^T, and its von Mises equivalent.
  const double J = F.determinant();
  const Mat3 sig = (std::abs(J) > 1e-12 ? 1.0 / J : 0.0) * (s.P * F.transpose());
  s.von_mises = von_mises_of(sig);
  return s;
}

namespace {

StressState stress_of(const SolidParams& sp, const Mat3& F) {
  return sp.neo_hookean ? neo_hookean_stress(F, sp.lambda, sp.mu) : svk_stress(F, sp.lambda, sp.mu);
}

}  // namespace

StressState neo_hookean_stress(const Mat3& F, double lambda, double mu) {
  StressState s;
  const double J = std::max(F.determinant(), 0.01);
  const Mat3 Finv = std::abs(F.determinant()) > 1e-12 ? Mat3(F.inverse()) : Mat3::Zero();
  const Mat3 FinvT = Finv.transpose();
  const double lnJ = std::log(J);
  s.P = mu * (F - FinvT) + lambda * lnJ * FinvT;
  s.S = Finv * s.P;
  const Mat3 C = F.transpose() * F;
  s.energy_density = 0.5 * mu * (C.trace() - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
  // Cauchy stress sigma = (mu (b - I) + lambda ln J I) / J, b = F F^T.
  const Mat3 sig = (mu * (F * F.transpose() - Mat3::Identity()) + lambda * lnJ * Mat3::Identity()) / J;
  s.von_mises = von_mises_of(sig);
  return s;
}

Solids::Solids(const Particles& P, const std::vector<Material>& materials, const CubicSpline& kernel,
               double dx, const std::vector<uint8_t>& clamped)
    : kernel_(&kernel) {
  params_.resize(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    if (materials[m].type == MaterialType::Elastic) params_[m] = SolidParams(materials[m]);

  const double volume = dx * dx * dx;
  min_mass_ = std::numeric_limits<double>::max();
  uint32_t max_id = 0;
  for (std::size_t i = 0; i < P.size(); ++i) max_id = std::max(max_id, P.id[i]);
  s_of_id_.assign(P.size() == 0 ? 0 : max_id + 1, kNone);
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Elastic) continue;
    const SolidParams& sp = params_[P.material[i]];
    s_of_id_[P.id[i]] = static_cast<uint32_t>(id_.size());
    id_.push_back(P.id[i]);
    X_.push_back(P.x0[i]);
    volume_.push_back(volume);
    mass_.push_back(sp.rho0 * volume);
    material_.push_back(P.material[i]);
    clamped_.push_back(clamped.empty() ? 0 : clamped[i]);
    max_c_ = std::max(max_c_, sp.c);
    min_mass_ = std::min(min_mass_, sp.rho0 * volume);
  }
  const std::size_t n = X_.size();
  F_.assign(n, Mat3::Identity());
  P_.assign(n, Mat3::Zero());
  vm_.assign(n, 0.0);
  reindex(P);
  if (n == 0) return;

  // Reference neighbours: pairs of one body within the kernel support in the reference configuration.
  NeighborSearch nb;
  nb.build(X_, kernel.support);
  std::vector<uint16_t> body(n);
  for (std::size_t s = 0; s < n; ++s) body[s] = P.body[at_[s]];
  offset_.assign(n + 1, 0);
  for (std::size_t s = 0; s < n; ++s) {
    uint32_t count = 0;
    for (uint32_t k = nb.begin(s); k < nb.end(s); ++k) count += body[nb.index()[k]] == body[s];
    offset_[s + 1] = offset_[s] + count;
  }
  nbr_.resize(offset_[n]);
  for (std::size_t s = 0; s < n; ++s) {
    uint32_t out = offset_[s];
    for (uint32_t k = nb.begin(s); k < nb.end(s); ++k)
      if (const uint32_t t = nb.index()[k]; body[t] == body[s]) nbr_[out++] = t;
  }

  // Correction matrices (Bonet & Lok 1999): L_s = (sum_t V_t grad_s W_st (x) (X_t - X_s))^-1. Where the
  // neighbours do not span three dimensions (a single layer of particles) the pseudo-inverse corrects what
  // they do span.
  std::vector<Mat3> L(n);
  parallel_for(n, [&](std::size_t s) {
    Mat3 M = Mat3::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const Vec3 Xst = X_[s] - X_[t];
      M += volume_[t] * kernel.gradW(Xst, Xst.norm()) * (X_[t] - X_[s]).transpose();
    }
    const double scale = M.trace() / 3.0;
    if (std::abs(M.determinant()) > 1e-3 * std::abs(scale * scale * scale))
      L[s] = M.inverse();
    else
      L[s] = M.completeOrthogonalDecomposition().pseudoInverse();
  });
  // Second-order correction: the gradient of a quadratic fit. The first-order gradient above is that of the
  // kernel-weighted linear fit of the neighbourhood, and where the neighbourhood is one-sided (every surface
  // particle) a curved field's fit has the slope of the neighbourhood's centroid, not of the particle: in a
  // bent beam the outer layers see the strain of a layer further in. A 4-layer beam stored only 66 % of the
  // bending energy of the exact Euler-Bernoulli mode (its period came out 1.26-1.31 x). The fit
  // u_t - u_s = a . p(X_t - X_s), p = (dx, dy, dz, dx^2, dy^2, dz^2, dx dy, dy dz, dz dx), weighted by V_t
  // W_st (moving least squares, Lancaster & Salkauskas 1981; the gradient is a's first three entries) is
  // exact for quadratic fields, so also for uniform bending. It is again a weight vector per pair, F_s =
  // sum_t V_t (x_t - x_s) (x) g_st, so eq. (18) and its energy consistency are unchanged. Where the quadratic
  // fit is not determined (fewer than three distinct rows in some direction: one or two layers) the
  // first-order gradient stays.
  std::vector<uint8_t> second(n, 0);
  std::vector<Eigen::Matrix<double, 9, 9>> Minv(n);
  auto basis = [](const Vec3& d) {
    Eigen::Matrix<double, 9, 1> p;
    p << d.x(), d.y(), d.z(), d.x() * d.x(), d.y() * d.y(), d.z() * d.z(), d.x() * d.y(), d.y() * d.z(),
        d.z() * d.x();
    return p;
  };
  parallel_for(n, [&](std::size_t s) {
    if (!params_[material_[s]].second_order) return;
    // Scaled by dx so that the matrix entries are of order one.
    Eigen::Matrix<double, 9, 9> M = Eigen::Matrix<double, 9, 9>::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const Vec3 d = (X_[t] - X_[s]) / dx;
      const auto p = basis(d);
      M += (volume_[t] * kernel.W(d.norm() * dx)) * p * p.transpose();
    }
    // Conditioning: a direction with too few distinct rows leaves M singular or nearly so.
    const auto sv = Eigen::JacobiSVD<Eigen::Matrix<double, 9, 9>>(M).singularValues();
    if (sv(8) > 1e-6 * sv(0)) {
      Minv[s] = Eigen::FullPivLU<Eigen::Matrix<double, 9, 9>>(M).inverse();
      second[s] = 1;
    }
  });
  // Second-order weights may not be much larger than first-order ones: a one-sided quadratic fit extrapolates
  // (3.3 x at a lattice's surface), and where the fit is barely determined (irregular, curved, thin: some
  // leaflet particles) the weights grow without bound, and with them the highest frequency. Above 4 x the
  // particle keeps the first-order gradient.
  parallel_for(n, [&](std::size_t a) {
    if (!second[a]) return;
    double g1 = 0.0, g2 = 0.0;
    for (uint32_t k = offset_[a]; k < offset_[a + 1]; ++k) {
      const Vec3 d = X_[nbr_[k]] - X_[a];
      g1 = std::max(g1, (L[a] * kernel.gradW(-d, d.norm())).norm());
      const Eigen::Matrix<double, 9, 1> c = Minv[a] * basis(d / dx) * kernel.W(d.norm());
      g2 = std::max(g2, Vec3(c(0), c(1), c(2)).norm() / dx);
    }
    if (g2 > 4.0 * g1) second[a] = 0;
  });
  g_ij_.resize(nbr_.size());
  g_ji_.resize(nbr_.size());
  w_ij_.resize(nbr_.size());
  // g of particle a towards b: first order L_a grad_a W(X_a - X_b); second order the gradient rows of
  // M_a^-1 p(X_b - X_a) W_ab (per unit volume of b).
  auto g_of = [&](std::size_t a, std::size_t b) -> Vec3 {
    const Vec3 d = X_[b] - X_[a];
    const double r = d.norm();
    if (!second[a]) return L[a] * kernel.gradW(X_[a] - X_[b], r);
    const Eigen::Matrix<double, 9, 1> c = Minv[a] * basis(d / dx) * kernel.W(r);
    return Vec3(c(0), c(1), c(2)) / dx;
  };
  parallel_for(n, [&](std::size_t s) {
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      g_ij_[k] = g_of(s, t);
      g_ji_[k] = g_of(t, s);
      w_ij_[k] = kernel.W((X_[s] - X_[t]).norm());
    }
  });
}

void Solids::reindex(const Particles& P) {
  map_slots(P, Kind::Elastic, s_of_id_, id_, X_, "elastic", at_, slot_);
}

Mat3 Solids::deformation_gradient(const Particles& P, std::size_t s) const {
  if (offset_[s] == offset_[s + 1]) return Mat3::Identity();  // an isolated particle carries no stress
  const Vec3 xs = P.x[at_[s]];
  // eq. (14), corrected: F_s = sum_t V_t (x_t - x_s) (x) g_st
  Mat3 F = Mat3::Zero();
  for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
    const uint32_t t = nbr_[k];
    F += volume_[t] * (P.x[at_[t]] - xs) * g_ij_[k].transpose();
  }
  return F;
}

namespace {

// Stiffness of the hourglass spring between s and t (Ganzenmueller 2015, eq. 22): alpha E V_s V_t W / |X|^2,
// shared by the two ends.
double hourglass_stiffness(const SolidParams& sp, double Vs, double Vt, double W, double X2) {
  return 0.5 * sp.hourglass * sp.E * Vs * Vt * W / X2;
}

// The pair's mean deviation along the pair, delta = ((F_s X - x) . e + (F_t X - x) . e) / 2, with X = X_t -
// X_s, x = x_t - x_s, e = x / |x|.
double hourglass_delta(const Mat3& Fs, const Mat3& Ft, const Vec3& X, const Vec3& x, const Vec3& e) {
  return 0.5 * ((Fs * X - x).dot(e) + (Ft * X - x).dot(e));
}

}  // namespace

// Hourglass control (Ganzenmueller 2015, eqs. 19-23). For a pair s-t, eps = F_s X_st - x_st is where F_s
// puts t relative to where t is; delta = (delta_s + delta_t) / 2 is its component along the pair averaged
// with t's view, zero for every affine deformation. Ganzenmueller pushes it back with a spring of stiffness
// k. Here the spring is an energy, U = sum over pairs of k delta^2 / 2, and the force is its exact gradient:
// the pair term -k delta d(delta)/dx (with the turn of the pair's direction) plus the part through F_s and
// F_t, which has the form of eq. (18) with the stress dU/dF_s / V_s = Q_s / V_s, Q_s = sum_t k delta / 2 e
// (x) X. Ganzenmueller's force leaves both out and does not conserve energy: an undamped beam with alpha = 10
// blew up, with alpha = 1 its energy oscillated by 1.2 %.
void Solids::update_stress(const Particles& P) {
  parallel_for(X_.size(), [&](std::size_t s) {
    const Mat3 F = deformation_gradient(P, s);
    const SolidParams& sp = params_[material_[s]];
    const StressState st = stress_of(sp, F);
    F_[s] = F;
    P_[s] = st.P;
    vm_[s] = st.von_mises;
  });
  hourglass_pair_.resize(nbr_.size());
  P_force_.resize(X_.size());
  parallel_for(X_.size(), [&](std::size_t s) {
    const SolidParams& sp = params_[material_[s]];
    P_force_[s] = P_[s];
    if (sp.hourglass <= 0.0) return;
    const Vec3 xs = P.x[at_[s]];
    Mat3 Q = Mat3::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const Vec3 xij = P.x[at_[t]] - xs;  // from s to t, current
      const double r = xij.norm();
      if (r <= 0.0) {
        hourglass_pair_[k] = Vec3::Zero();
        continue;
      }
      const Vec3 e = xij / r, X = X_[t] - X_[s];
      const double delta = hourglass_delta(F_[s], F_[t], X, xij, e);
      const double k_hg = hourglass_stiffness(sp, volume_[s], volume_[t], w_ij_[k], X.squaredNorm());
      Q += (0.5 * k_hg * delta) * e * X.transpose();
      // The pair term on s, k delta d(delta)/dx_s with d(delta)/dx_s = e - (I - e e^T) eps_mean / r
      // (add_forces() subtracts it).
      const Vec3 eps = 0.5 * (F_[s] + F_[t]) * X - xij;
      hourglass_pair_[k] = (k_hg * delta) * (e - (eps - eps.dot(e) * e) / r);
    }
    P_force_[s] += Q / volume_[s];
  });
}

void Solids::add_forces(const Particles& P, std::vector<Vec3>& f) const {
  const CubicSpline& K = *kernel_;
  const double h = K.h;
  const double eta2 = 0.01 * h * h;
  parallel_for_dynamic(X_.size(), [&](std::size_t s) {
    const uint32_t i = at_[s];
    if (clamped_[s]) return;  // held at its reference position: no force needed
    const SolidParams& sp = params_[material_[s]];
    const Vec3 xi = P.x[i], vi = P.v[i];
    Vec3 elastic = Vec3::Zero(), other = Vec3::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const uint32_t j = at_[t];
      // eq. (18) with corrected gradients: f_s = V_s sum_t V_t (P_s g_st - P_t g_ts); P with the hourglass
      // energy's share (update_stress()).
      elastic += volume_[t] * (P_force_[s] * g_ij_[k] - P_force_[t] * g_ji_[k]);

      const Vec3 xij = P.x[j] - xi;  // from s to t, current
      const double r = xij.norm();
      if (r <= 0.0) continue;
      // Hourglass control, the pair term found by update_stress().
      if (sp.hourglass > 0.0) other -= hourglass_pair_[k];
      // Artificial viscosity (Monaghan 1992) for approaching pairs, on the current distance.
      if (sp.alpha > 0.0) {
        const Vec3 x_ij = -xij;  // x_s - x_t
        const double vx = (vi - P.v[j]).dot(x_ij);
        if (vx < 0.0) {
          const double mu = h * vx / (r * r + eta2);
          const double Pi = -sp.alpha * sp.c * mu / sp.rho0;
          other -= (mass_[s] * mass_[t] * Pi * K.dWdr(r) / r) * x_ij;
        }
      }
    }
    f[i] += volume_[s] * elastic + other;
  });
}

double Solids::elastic_energy(const Particles& P) const {
  const std::size_t n = X_.size();
  std::vector<Mat3> F(n);
  parallel_for(n, [&](std::size_t s) { F[s] = deformation_gradient(P, s); });
  return parallel_reduce(
      n, 0.0,
      [&](std::size_t s) {
        const SolidParams& sp = params_[material_[s]];
        double e = volume_[s] * stress_of(sp, F[s]).energy_density;
        // The hourglass springs' energy (add_forces): 1/2 k delta^2 per pair, k = alpha E V_s V_t W / |X|^2 /
        // 2, half of it from each end. The force is this energy's gradient with F held fixed; without this
        // term an undamped beam's energy dips by what the springs hold (2 % at alpha = 1).
        if (sp.hourglass > 0.0) {
          const Vec3 xs = P.x[at_[s]];
          for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
            const uint32_t t = nbr_[k];
            const Vec3 xij = P.x[at_[t]] - xs;
            const double r = xij.norm();
            if (r <= 0.0) continue;
            const Vec3 e_ij = xij / r, X = X_[t] - X_[s];
            const double delta = hourglass_delta(F[s], F[t], X, xij, e_ij);
            const double stiffness =
                hourglass_stiffness(sp, volume_[s], volume_[t], w_ij_[k], X.squaredNorm());
            e += 0.25 * stiffness * delta * delta;
          }
        }
        return e;
      },
      [](double a, double b) { return a + b; });
}

}  // namespace aortasph
