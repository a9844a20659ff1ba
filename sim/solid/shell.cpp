#include "solid/shell.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/neighbors.hpp"
#include "core/parallel.hpp"
#include "core/sim_errors.hpp"
#include "core/slot_map.hpp"
#include "geometry/shapes.hpp"

namespace aortasph {

namespace {

// Gauss-Legendre rules on [-1, 1] through the thickness (zeta = t/2 xi): 2 points for Saint Venant-Kirchhoff
// (exact for its energy, quadratic in zeta at small strain), 3 for neo-Hookean. Slot 0 is the mid-surface
// (xi = 0) in both, for J0 at zeta = 0; the 2-point rule gives it weight 0.
constexpr double kXi2[3] = {0.0, -0.5773502691896258, 0.5773502691896258};
constexpr double kW2[3] = {0.0, 1.0, 1.0};
constexpr double kXi3[3] = {0.0, -0.7745966692414834, 0.7745966692414834};
constexpr double kW3[3] = {8.0 / 9.0, 5.0 / 9.0, 5.0 / 9.0};
// The hourglass control's stiffness across the sheet relative to the membrane's, c in beta = c (t / |X|)^2
// (Shells::update).
constexpr double kHgTransverse = 3.0;

Mat3 columns(const Shells::Mat32& A, const Vec3& c) {
  Mat3 J;
  J.leftCols<2>() = A;
  J.col(2) = c;
  return J;
}

double von_mises_plane(const Mat3& S) {
  const double a = S(0, 0), b = S(1, 1), c = S(0, 1);
  return std::sqrt(a * a - a * b + b * b + 3.0 * (c * c + S(0, 2) * S(0, 2) + S(1, 2) * S(1, 2)));
}

// The membrane correction's saturation: at most about this much strain (Shells::update).
constexpr double kCorrectionMax = 0.01;

// The curvature in the reference tangent coordinates, B = -sym(G^T H) (G the tangents, H the director
// gradient).
Shells::Mat2 curvature(const Shells::Mat32& G, const Shells::Mat32& H) {
  const Shells::Mat2 GH = G.transpose() * H;
  return -0.5 * (GH + GH.transpose());
}

// Q(B)_dl = sum_abc B_dc B_ab m3[abcl]: the tangential part of the third-order Taylor term that the linear
// gradient weights leave in G (see Shells::update).
Shells::Mat2 curvature_moment(const Shells::Mat2& B, const std::array<double, 16>& m3) {
  Shells::Mat2 Q = Shells::Mat2::Zero();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c)
        for (int l = 0; l < 2; ++l) {
          const double m = B(a, b) * m3[8 * a + 4 * b + 2 * c + l];
          Q(0, l) += B(0, c) * m;
          Q(1, l) += B(1, c) * m;
        }
  return Q;
}

}  // namespace

Shells::Shells(const Particles& P, const std::vector<Material>& materials, const CubicSpline& kernel,
               const std::vector<ShellSeed>& seed, const Periodic& per)
    : h_(kernel.h), per_(per) {
  params_.resize(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    if (materials[m].type == MaterialType::Shell) params_[m] = ShellParams(materials[m]);
  for (const ShellParams& p : params_) stiffens_ = stiffens_ || p.c1 > 0.0;
  for (const ShellParams& p : params_) viscous_ = viscous_ || p.eta > 0.0;
  uint32_t max_id = 0;
  for (std::size_t i = 0; i < P.size(); ++i) max_id = std::max(max_id, P.id[i]);
  s_of_id_.assign(P.size() == 0 ? 0 : max_id + 1, kNone);
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.kind[i] != Kind::Shell) continue;
    const ShellParams& sp = params_[P.material[i]];
    s_of_id_[P.id[i]] = static_cast<uint32_t>(id_.size());
    id_.push_back(P.id[i]);
    X_.push_back(P.x0[i]);
    const Vec3 n = seed[i].normal.normalized();
    N_.push_back(n);
    Vec3 u, v;
    perpendicular_frame(n, u, v);  // (u, v, n) orthonormal, right-handed
    T1_.push_back(u);
    T2_.push_back(v);
    const Vec3 f = seed[i].fibre - seed[i].fibre.dot(n) * n;
    const double fl = f.norm();
    fibre_.push_back(fl > 1e-9 ? Eigen::Vector2d(u.dot(f) / fl, v.dot(f) / fl) : Eigen::Vector2d(0.0, 0.0));
    area_.push_back(seed[i].area);
    mass_.push_back(sp.rho0 * sp.t * seed[i].area);
    inertia_.push_back(sp.rho0 * sp.t * sp.t * sp.t / 12.0 * seed[i].area);
    material_.push_back(P.material[i]);
    support_.push_back(seed[i].support);
  }
  const std::size_t n = X_.size();
  d_ = N_;
  omega_.assign(n, Vec3::Zero());
  reindex(P);
  if (n == 0) return;

  // Reference neighbours within the kernel support, of one body.
  NeighborSearch nb;
  nb.set_periodic(per_);
  nb.build(X_, kernel.support);
  std::vector<uint16_t> body(n);
  for (std::size_t s = 0; s < n; ++s) body[s] = P.body[at_[s]];
  offset_.assign(n + 1, 0);
  for (std::size_t s = 0; s < n; ++s) {
    uint32_t count = 0;
    for (uint32_t k = nb.begin(s); k < nb.end(s); ++k) {
      const uint32_t t = nb.index()[k];
      count += t != s && body[t] == body[s];
    }
    offset_[s + 1] = offset_[s] + count;
  }
  nbr_.resize(offset_[n]);
  for (std::size_t s = 0; s < n; ++s) {
    uint32_t out = offset_[s];
    for (uint32_t k = nb.begin(s); k < nb.end(s); ++k)
      if (const uint32_t t = nb.index()[k]; t != s && body[t] == body[s]) nbr_[out++] = t;
  }
  rev_.resize(nbr_.size());
  parallel_for(n, [&](std::size_t s) {
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      rev_[k] = kNone;
      for (uint32_t l = offset_[t]; l < offset_[t + 1]; ++l)
        if (nbr_[l] == s) rev_[k] = l;
    }
  });

  // In-plane corrected gradient weights (Wu et al. 2023, the reduced correction matrix): in s's tangent
  // frame, a_st = (T1.X_st, T2.X_st), h_st = W'(r) a_st / r, g_st = L_s h_st with L_s = (sum_t A_t h_st
  // a_st^T)^-1, so that sum_t A_t (f_t - f_s) g_st^T is exact for every field linear in the tangent plane.
  g_.resize(nbr_.size());
  std::vector<double> ksum(n, 0.0);
  // Particles near an edge (over_sheet): the first moment of the reference neighbourhood over 0.08 of the
  // neighbours' mean distance (about 0.1 dx on a lattice at h = 1.3 dx).
  edge_.assign(n, 0);
  parallel_for(n, [&](std::size_t s) {
    Vec3 moment = Vec3::Zero();
    double dist = 0.0;
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const Vec3 X = sep(X_[nbr_[k]], X_[s]);
      const double w = kernel.W(X.norm());
      moment += w * X;
      dist += w * X.norm();
    }
    edge_[s] = offset_[s] == offset_[s + 1] || moment.norm() > 0.08 * dist;
  });
  parallel_for(n, [&](std::size_t s) {
    Mat2 M = Mat2::Zero();
    std::vector<Eigen::Vector2d> hv(offset_[s + 1] - offset_[s]);
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const Vec3 X = sep(X_[nbr_[k]], X_[s]);
      const double r = X.norm();
      const Eigen::Vector2d a(T1_[s].dot(X), T2_[s].dot(X));
      const Eigen::Vector2d hh = (kernel.dWdr(r) / r) * a;
      hv[k - offset_[s]] = hh;
      M += area_[nbr_[k]] * hh * a.transpose();
      ksum[s] += area_[nbr_[k]] * kernel.W(r);
    }
    const Mat2 L = std::abs(M.determinant()) > 1e-12 * M.squaredNorm() ? Mat2(M.inverse()) : Mat2::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) g_[k] = L * hv[k - offset_[s]];
  });
  m3_.assign(n, {});
  parallel_for(n, [&](std::size_t s) {
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const Vec3 X = sep(X_[nbr_[k]], X_[s]);
      const double a[2] = {T1_[s].dot(X), T2_[s].dot(X)};
      for (int i = 0; i < 16; ++i)
        m3_[s][i] += area_[nbr_[k]] * a[i >> 3] * a[(i >> 2) & 1] * a[(i >> 1) & 1] * g_[k](i & 1);
    }
  });

  // The Kelvin-Voigt viscosity's step bound (stable_dt): a Gershgorin bound on the largest rate of its
  // linearised operator, f_s = -sum_w D_sw v_w. The force on s gathers PG_s (weight sum_t A_t g_st, at most
  // gamma_s = sum_t A_t |g_st|) and PG_t (weight A_s |g_ts|), each PG_u ~ 2 eta V_u G'_u with |G'_u| at
  // most 2 gamma_u max |v|, so sum_w |D_sw| / m_s <= (2 eta / rho) lambda_s with lambda_s = 2 gamma_s^2 +
  // 2 sum_t A_t |g_ts| gamma_t [1/m^2], a property of the reference stencil. (Morris, Fox & Zhu 1997's
  // 0.125 h^2 / nu, the usual SPH viscous bound, is made for the kernel Laplacian, not for this nested
  // gradient with corrected weights: here h^2 lambda is 21-28 on the leaflets, so the bound below is
  // 0.036 h^2 / nu at cfl 0.5.)
  if (viscous_) {
    std::vector<double> gam(n, 0.0), lam(n, 0.0);
    parallel_for(n, [&](std::size_t s) {
      for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) gam[s] += area_[nbr_[k]] * g_[k].norm();
    });
    parallel_for(n, [&](std::size_t s) {
      double l = 2.0 * gam[s] * gam[s];
      for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k)
        if (rev_[k] != kNone) l += 2.0 * area_[nbr_[k]] * g_[rev_[k]].norm() * gam[nbr_[k]];
      lam[s] = l;
    });
    visc_lambda_.assign(params_.size(), 0.0);
    for (std::size_t s = 0; s < n; ++s)
      visc_lambda_[material_[s]] = std::max(visc_lambda_[material_[s]], lam[s]);
  }

  // Reference mid-surface tangents G0, director gradient H0 and, per Gauss point, J0^-1 and the volume.
  K0_.resize(kGauss * n);
  vol_.resize(kGauss * n);
  q3ref_.resize(n);
  b_.resize(nbr_.size());
  k_hg_.resize(nbr_.size());
  parallel_for(n, [&](std::size_t s) {
    const ShellParams& sp = params_[material_[s]];
    Mat32 G0 = Mat32::Zero(), H0 = Mat32::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      G0 += area_[t] * sep(X_[t], X_[s]) * g_[k].transpose();
      H0 += area_[t] * (N_[t] - N_[s]) * g_[k].transpose();
    }
    if (offset_[s] == offset_[s + 1]) G0 << T1_[s], T2_[s];
    q3ref_[s] = curvature_moment(curvature(G0, H0), m3_[s]);
    const double det0 = columns(G0, N_[s]).determinant();
    const double* xi = sp.neo_hookean ? kXi3 : kXi2;
    const double* wq = sp.neo_hookean ? kW3 : kW2;
    for (int q = 0; q < kGauss; ++q) {
      const double zeta = 0.5 * sp.t * xi[q];
      const Mat3 J0 = columns(G0 + zeta * H0, N_[s]);
      const double det = J0.determinant();
      K0_[kGauss * s + q] = std::abs(det) > 1e-12 ? Mat3(J0.inverse()) : Mat3::Identity();
      vol_[kGauss * s + q] = area_[s] * wq[q] * 0.5 * sp.t * (std::abs(det0) > 1e-12 ? det / det0 : 1.0);
    }
    const Mat3& K = K0_[kGauss * s];
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const Vec3 X = sep(X_[t], X_[s]);
      b_[k] = K * X;
      // Hourglass stiffness: alpha E t / (1 - nu^2) A_s A_t W / (|X|^2 Wbar), Wbar the mean kernel sum of
      // the pair, so that sum_t k |eps|^2 ~ alpha (E t) A |grad eps|^2: the membrane stiffness' scale.
      const double wbar = 0.5 * (ksum[s] + ksum[t]);
      k_hg_[k] = sp.hourglass * sp.E * sp.t / (1.0 - sp.nu * sp.nu) * area_[s] * area_[t] *
                 kernel.W(X.norm()) / (X.squaredNorm() * std::max(wbar, 1e-300));
    }
  });

  x_.resize(n);
  if (viscous_) {
    Gd_.assign(n, Mat32::Zero());
    Hd_.assign(n, Mat32::Zero());
    dd_.assign(n, Vec3::Zero());
  }
  G_.assign(n, Mat32::Zero());
  normal_.assign(n, Vec3::Zero());
  has_normal_.assign(n, 0);
  H_.assign(n, Mat32::Zero());
  PG_.assign(n, Mat32::Zero());
  PH_.assign(n, Mat32::Zero());
  q_.assign(n, Vec3::Zero());
  hg_force_.assign(n, Vec3::Zero());
  force_.assign(n, Vec3::Zero());
  torque_.assign(n, Vec3::Zero());
  F0_.assign(n, Mat3::Identity());
  energy_.assign(n, 0.0);
  vm_.assign(n, 0.0);
  strain_.assign(n, 0.0);
  stiffening_.assign(n, 1.0);
  // The unstrained stiffening: 1, except where fibres stiffen the sheet from the start (their W44 at I4 = 1).
  for (std::size_t s = 0; s < n; ++s)
    if (params_[material_[s]].c1 > 0.0) {
      Mat3 S;
      double psi = 0.0;
      shell_stress(params_[material_[s]], Mat3::Zero(), S, psi, &stiffening_[s], &fibre_[s]);
    }
  Nres_.assign(n, Mat2::Zero());
  Mres_.assign(n, Mat2::Zero());
  Qres_.assign(n, Eigen::Vector2d::Zero());
}

void Shells::reindex(const Particles& P) {
  map_slots(P, Kind::Shell, s_of_id_, id_, X_, "shell", at_, slot_);
}

void Shells::update(const Particles& P, const std::vector<Vec3>* v) {
  parallel_for(X_.size(), [&](std::size_t s) { x_[s] = P.x[at_[s]]; });
  v_ = viscous_ && v && v->size() == X_.size() ? v : nullptr;
  compute();
  v_ = nullptr;
}

void Shells::restore_update(std::vector<Vec3> x, std::vector<Vec3> d) {
  x_ = std::move(x);
  d_.swap(d);  // compute() reads d_: the directors of that update, then the current ones back
  compute();
  d_.swap(d);
}

void Shells::compute() {
  const std::size_t n = X_.size();
  d_update_ = d_;
  // The directors' rates d' = omega x d (the Kelvin-Voigt stress only), once per particle.
  if (v_) parallel_for(n, [&](std::size_t s) { dd_[s] = omega_[s].cross(d_[s]); });
  // Mid-surface tangents and director gradient.
  parallel_for(n, [&](std::size_t s) {
    Mat32 G = Mat32::Zero(), H = Mat32::Zero();
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      G += area_[t] * sep(x_[t], x_[s]) * g_[k].transpose();
      H += area_[t] * (d_[t] - d_[s]) * g_[k].transpose();
    }
    if (offset_[s] == offset_[s + 1]) G << T1_[s], T2_[s];
    G_[s] = G;
    H_[s] = H;
    if (v_) {  // their rates (the Kelvin-Voigt stress): G' from the velocities, H' from d' = omega x d
      const std::vector<Vec3>& v = *v_;
      Mat32 Gd = Mat32::Zero(), Hd = Mat32::Zero();
      for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
        const uint32_t t = nbr_[k];
        Gd += area_[t] * (v[t] - v[s]) * g_[k].transpose();
        Hd += area_[t] * (dd_[t] - dd_[s]) * g_[k].transpose();
      }
      Gd_[s] = Gd;
      Hd_[s] = Hd;
    }
    const Vec3 nrm = G.col(0).cross(G.col(1));
    const double len = nrm.norm();
    has_normal_[s] = len > 0.0;
    normal_[s] = len > 0.0 ? Vec3(nrm / len) : Vec3::Zero();
    F0_[s] = columns(G, d_[s]) * K0_[kGauss * s];
  });
  // Stress at the Gauss points, resultants and the energy's derivatives by G, H and d.
  parallel_for(n, [&](std::size_t s) {
    const ShellParams& sp = params_[material_[s]];
    Mat3 Q0;
    Q0 << T1_[s], T2_[s], N_[s];
    Mat32 PG = Mat32::Zero(), PH = Mat32::Zero();
    Vec3 q = Vec3::Zero();
    double U = 0.0, vm = 0.0, strain = -1e300, stiff = 1.0;
    Mat2 Nr = Mat2::Zero(), Mr = Mat2::Zero();
    Eigen::Vector2d Qr = Eigen::Vector2d::Zero();
    // The membrane strain's curvature correction (docs/model.md "Shells", membrane locking): the linear
    // gradient weights measure G with a third-order error whose tangential part, for a sheet bent without
    // stretching, is G C with C = (Q(B0) - Q(B)) / 6 (Gauss-Codazzi in the reference's tangent-plane
    // coordinates a: G_d . x_,abc = b0_dc b0_ab - b_dc b_ab); the metric then reads sym(C) too much, which
    // the in-plane strain gives back. Zero for every rigid motion and every flat sheet bent in its plane;
    // linear in the change of curvature on a curved sheet, where it is what locked the bending modes.
    // The series behind it holds for |B| dx small; where a sheet folds within a few spacings (a crease, a
    // coapting free edge) it is saturated smoothly at kCorrectionMax of strain, C_eff = s C with s = (1 +
    // (|C| / c0)^2)^(-1/2), so that it cannot swamp the strain it corrects (unsaturated, the closed leaflets
    // of aortic_valve_cycle_physio.json sped up to 32 m/s within 20 ms).
    const Mat2 B = curvature(G_[s], H_[s]);
    const Mat2 C = (q3ref_[s] - curvature_moment(B, m3_[s])) / 6.0;
    const Mat2 Cs = 0.5 * (C + C.transpose());
    const double cx = Cs.norm() / kCorrectionMax;
    const double sat = 1.0 / std::sqrt(1.0 + cx * cx);
    const Mat2 Csym = sat * Cs;
    Mat2 Nt = Mat2::Zero();  // sum of V S (in-plane): dU / dC_eff = -Nt
    const double* xi = sp.neo_hookean ? kXi3 : kXi2;
    for (int k = sp.neo_hookean ? 0 : 1; k < kGauss; ++k) {
      const double zeta = 0.5 * sp.t * xi[k];
      const Mat3& K = K0_[kGauss * s + k];
      const Mat3 F = columns(G_[s] + zeta * H_[s], d_[s]) * K;
      const Mat3 Eg = 0.5 * (F.transpose() * F - Mat3::Identity());
      Mat3 El = Q0.transpose() * Eg * Q0;
      El.topLeftCorner<2, 2>() -= Csym;
      Mat3 Sl;
      double psi = 0.0, st = 1.0;
      shell_stress(sp, El, Sl, psi, sp.c1 > 0.0 ? &st : nullptr, &fibre_[s]);
      stiff = std::max(stiff, st);
      const double V = vol_[kGauss * s + k];
      U += V * psi;
      Nt += V * Sl.topLeftCorner<2, 2>();
      vm = std::max(vm, von_mises_plane(Sl));
      const double em = 0.5 * (El(0, 0) + El(1, 1)), ed = 0.5 * (El(0, 0) - El(1, 1));
      strain = std::max(strain, em + std::sqrt(ed * ed + El(0, 1) * El(0, 1)));
      // Resultants per unit length: the through-thickness integrals of S (sum of w_k t/2 S).
      const double wt = V / area_[s];
      Nr += wt * Sl.topLeftCorner<2, 2>();
      Mr += wt * zeta * Sl.topLeftCorner<2, 2>();
      Qr += wt * Sl.block<2, 1>(0, 2);
      // Kelvin-Voigt viscosity (`dynamic_viscosity` eta; Holzapfel 2000, "Nonlinear Solid Mechanics",
      // sect. 6.10: S = S_elastic + S_viscous): S_v = 2 eta E' on the in-plane components, E' = sym(F^T F')
      // the Green-Lagrange strain rate with F' = [G' + zeta H' | d'] K from the velocities and the
      // directors' spin. Through zeta it damps bending as well as stretching. The transverse shear is left
      // undamped (its rate acts on the small rotary inertia rho t^3 / 12 and would bound the sub-step by
      // ~t^2 rho / eta). A dissipation only: the forces below are the same contraction as the elastic
      // ones, so their power is -sum V S_v : E' <= 0. Not in the energy, the resultants or the reported
      // stress (those are the elastic tissue's; a steady load has E' = 0).
      Mat3 St = Sl;
      if (v_ && sp.eta > 0.0) {
        const Mat3 Fd = columns(Gd_[s] + zeta * Hd_[s], dd_[s]) * K;
        const Mat3 Ft = F.transpose() * Fd;
        const Mat3 Ed = Q0.transpose() * (0.5 * (Ft + Ft.transpose())) * Q0;
        St.topLeftCorner<2, 2>() += 2.0 * sp.eta * Ed.topLeftCorner<2, 2>();
      }
      // dpsi/dF = F S (first Piola-Kirchhoff), dpsi/dJ = P K^T with J = [G + zeta H | d].
      const Mat3 Pk = F * (Q0 * St * Q0.transpose());
      const Mat3 dJ = V * Pk * K.transpose();
      PG += dJ.leftCols<2>();
      PH += zeta * dJ.leftCols<2>();
      q += dJ.col(2);
    }
    {  // dU/dB through C: dU = (1/6) sum_dl Nt_dl dQ_dl, dQ_dl = sum_abc (dB_dc B_ab + B_dc dB_ab) m3_abcl;
       // then B = -sym(G^T H) gives dU/dG = -H T, dU/dH = -G T with T = sym(dU/dB).
      // Through the saturation: dC_eff = s dC + (s' / |C|) (C : dC) C, s' / |C| = -s^3 / c0^2.
      const Mat2 Ne =
          sat * Nt - (sat * sat * sat / (kCorrectionMax * kCorrectionMax)) * (Nt.cwiseProduct(Cs).sum()) * Cs;
      const std::array<double, 16>& m3 = m3_[s];
      Mat2 T = Mat2::Zero();
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          for (int c = 0; c < 2; ++c)
            for (int l = 0; l < 2; ++l) {
              const double m = m3[8 * a + 4 * b + 2 * c + l] / 6.0;
              for (int d = 0; d < 2; ++d) {
                T(d, c) += Ne(d, l) * B(a, b) * m;
                T(a, b) += Ne(d, l) * B(d, c) * m;
              }
            }
      const Mat2 Ts = 0.5 * (T + T.transpose());
      PG -= H_[s] * Ts;
      PH -= G_[s] * Ts;
    }
    PG_[s] = PG;
    PH_[s] = PH;
    q_[s] = q;
    energy_[s] = U;
    vm_[s] = vm;
    strain_[s] = strain;
    stiffening_[s] = stiff;
    Nres_[s] = Nr;
    Mres_[s] = Mr;
    Qres_[s] = Qr;
  });
  // Hourglass energy: per pair eps = (F_s + F_t) X / 2 - x_st, U = 1/2 k |eps|^2 (each pair seen from both
  // ends, half the energy each). Its derivative by G_s, d_s goes into PG, q; the pair term into hg_force_.
  parallel_for(n, [&](std::size_t s) {
    const ShellParams& sp = params_[material_[s]];
    if (sp.hourglass <= 0.0) {
      hg_force_[s] = Vec3::Zero();
      return;
    }
    Vec3 fp = Vec3::Zero();
    Mat32 PG = Mat32::Zero();
    Vec3 q = Vec3::Zero();
    double U = 0.0;
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const Vec3 X = sep(X_[t], X_[s]);
      const double beta = std::min(1.0, kHgTransverse * sp.t * sp.t / X.squaredNorm());
      const Vec3 eps = 0.5 * (F0_[s] + F0_[t]) * X - sep(x_[t], x_[s]);
      const double kk = k_hg_[k];
      // The pair's energy 1/2 k eps^T A eps, A = I - (1 - beta) n n^T with n the pair's mean director: the
      // component of eps across the sheet (a transverse zig-zag of the pair) is penalised at the bending
      // scale, beta = c (t / |X|)^2 (capped at 1), not at the membrane's. With beta = 1 (the full membrane
      // stiffness across the sheet, as before) the smooth bending modes' third-order eps costs of the order
      // of alpha (h/t)^2 (h/L)^2 of their bending energy: a locking that made the clamped plate at dx = 4t
      // 17 % too stiff. c = 3 (kHgTransverse) is calibrated on that plate and checked on the others and on
      // Scordelis-Lo (docs/validation.md, "Shells"; c = 1/12, the bending-to-membrane stiffness ratio at
      // the pair's length, leaves the 4t plate 5 % soft and lets the zig-zag creep).
      const Vec3 dsum = d_[s] + d_[t];
      const double dlen = std::max(dsum.norm(), 1e-12);
      const Vec3 nn = dsum / dlen;
      const double en = eps.dot(nn), cb = 1.0 - beta;
      const Vec3 ea = eps - cb * en * nn;  // A eps
      U += 0.25 * kk * eps.dot(ea);
      // d eps / d G_s = 1/2 (.) b_s^T with b_s = K0_s X (first two entries), d eps / d d_s = 1/2 b_s(2);
      // d n / d d_s = (I - n n^T) / |d_s + d_t|.
      PG += 0.5 * kk * ea * b_[k].head<2>().transpose();
      q += 0.5 * kk * b_[k](2) * ea - kk * cb * en / dlen * (eps - en * nn);
      fp -= kk * ea;  // d eps / d x_s = +I
    }
    PG_[s] += PG;
    q_[s] += q;
    energy_[s] += U;
    hg_force_[s] = fp;
  });
  // Forces and director moments (gather): f_s = -dU/dx_s, gamma_s = -dU/dd_s, with G_t = sum_u A_u (x_u -
  // x_t) g_tu^T contributing A_s PG_t g_ts to dU/dx_s and -sum_u A_u PG_s g_su.
  parallel_for(n, [&](std::size_t s) {
    Vec3 f = hg_force_[s];
    Vec3 gam = -q_[s];
    for (uint32_t k = offset_[s]; k < offset_[s + 1]; ++k) {
      const uint32_t t = nbr_[k];
      const Eigen::Vector2d& gst = g_[k];
      const Eigen::Vector2d& gts = g_[rev_[k]];
      f += area_[t] * PG_[s] * gst - area_[s] * PG_[t] * gts;
      gam += area_[t] * PH_[s] * gst - area_[s] * PH_[t] * gts;
    }
    force_[s] = f;
    torque_[s] = d_[s].cross(gam);
  });
}

void Shells::add_forces(std::vector<Vec3>& f) const {
  parallel_for(X_.size(), [&](std::size_t s) { f[at_[s]] += force_[s]; });
}

void Shells::advance_directors(double dt, double kick) {
  parallel_for(X_.size(), [&](std::size_t s) {
    if (support_[s] == 1) {
      omega_[s] = Vec3::Zero();
      d_[s] = N_[s];
      return;
    }
    const double c = params_[material_[s]].damping;
    const Vec3 tau = external_.empty() ? torque_[s] : Vec3(torque_[s] + external_[s]);
    Vec3 w = omega_[s] + kick * (tau / inertia_[s] - c * omega_[s]);
    if (support_[s] == 4) w -= w.dot(free_axis_[s]) * free_axis_[s];  // a hard diaphragm
    w -= w.dot(d_[s]) * d_[s];  // no spin about the director (it has no inertia, nothing to turn)
    omega_[s] = w;
    const double angle = w.norm() * dt;
    if (angle > 0.0) {
      const Vec3 axis = w.normalized();
      const Vec3& d = d_[s];
      // Rodrigues' rotation of d about axis by angle.
      const Vec3 r = d * std::cos(angle) + axis.cross(d) * std::sin(angle) +
                     axis * axis.dot(d) * (1.0 - std::cos(angle));
      d_[s] = r.normalized();
    }
  });
}

double Shells::stable_dt(double cfl, double max_speed) const {
  // A stiffening law (Lee-Sacks) raises the wave speed with the strain: c_plate times the square root of
  // the largest stiffening of its particles at the last update() (1 for the other laws, and before any).
  std::vector<double> stiff(params_.size(), 1.0);
  if (stiffens_)
    for (std::size_t s = 0; s < stiffening_.size(); ++s)
      stiff[material_[s]] = std::max(stiff[material_[s]], stiffening_[s]);
  double dt = std::numeric_limits<double>::max();
  for (std::size_t m = 0; m < params_.size(); ++m) {
    const ShellParams& p = params_[m];
    if (p.t <= 0.0) continue;
    const double h = h_;
    const double c = stiff[m] > 1.0 ? p.c_plate * std::sqrt(stiff[m]) : p.c_plate;
    // Wu et al. 2023 / SPHinXsys ShellAcousticTimeStepSize: the in-plane wave crossing h, and the shear-
    // rotary (Mindlin) limit, which goes like t / c for h >> t.
    const double pi2 = std::numbers::pi * std::numbers::pi;
    const double rotary =
        h *
        std::sqrt(1.0 / (c * c) / (2.0 + pi2 / 12.0 * (1.0 - p.nu) * (1.0 + 1.5 * (h / p.t) * (h / p.t))));
    dt = std::min(dt, cfl * std::min(h / (c + max_speed), rotary));
    // Kelvin-Voigt viscosity: the damping's explicit (forward Euler) limit 2 / rate, the rate bounded by
    // (2 eta / rho) visc_lambda_ (the constructor's Gershgorin bound; bending resists per rotary inertia as
    // stretching per mass), times cfl.
    if (p.eta > 0.0 && visc_lambda_[m] > 0.0)  // sized to params_ whenever some eta > 0
      dt = std::min(dt, cfl * 2.0 / (2.0 * p.eta / p.rho0 * visc_lambda_[m]));
  }
  return dt;
}

double Shells::energy() const {
  return parallel_reduce(
      X_.size(), 0.0, [&](std::size_t s) { return energy_[s]; }, [](double a, double b) { return a + b; });
}

double Shells::rotational_energy() const {
  return parallel_reduce(
      X_.size(), 0.0, [&](std::size_t s) { return 0.5 * inertia_[s] * omega_[s].squaredNorm(); },
      [](double a, double b) { return a + b; });
}

}  // namespace aortasph
