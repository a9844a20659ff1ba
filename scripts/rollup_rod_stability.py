#!/usr/bin/python3
"""
Why the free cantilever strip of the shell roll-up validation leaves its plane (docs/validation.md, "Shells",
stop 33; written in this project for it). Run: /usr/bin/python3 scripts/rollup_rod_stability.py (numpy,
scipy; about a minute): prints the checks below and the critical load fraction lambda_c for b/t = 2, 4, 10.

Stability of the planar circular arc of a clamped Kirchhoff rod (strip) under a tip moment.

Discrete Kirchhoff rod (inextensible, unshearable): frames R_0 = I (clamp), R_1..R_N free,
link k between frames k-1 and k, length h = L/N, link energy
    U_k = 1/(2h) v^T K v,  v = log(R_{k-1}^T R_k) (material components), K = diag(C, A, B)
(axis 1 = tangent: torsion C; axis 2 = width: weak bending A; axis 3 = director d: lateral bending B).
Since the load is a pure moment and the rod is inextensible, positions do not enter the potential.

Load (conservative): V = -M theta(d_N), theta = atan2(-d_x, d_z) (unwrapped about the arc value).
Perturbation coordinates: body rotation vectors eta_k, R_k = R0_k exp(hat(eta_k)).

Hessian by finite differences of the *local* terms (every link of the arc has the same relative
rotation, so a single 6x6 link Hessian + a 3x3 tip-load Hessian suffice), assembled.

Also: continuum second-variation functional (derived analytically, see report) discretised by
P1 finite elements as an independent check; and a linearised dynamic check (translational +
rotary inertia) for the conservative load and for a dead (fixed-direction) moment -M e_y.
"""
import numpy as np
from scipy.spatial.transform import Rotation
from scipy.optimize import brentq
import scipy.linalg as sla

E = 1.2e6
G = E / 2
L = 12.0
RHO = 1000.0


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def expm(w):
    return Rotation.from_rotvec(w).as_matrix()


def logm(R):
    return Rotation.from_matrix(R).as_rotvec()


def Ry(a):
    return expm(np.array([0.0, a, 0.0]))


def Jr(w):
    th = np.linalg.norm(w)
    W = hat(w)
    if th < 1e-8:
        return np.eye(3) - 0.5 * W + W @ W / 6.0
    return np.eye(3) - (1 - np.cos(th)) / th**2 * W + (th - np.sin(th)) / th**3 * (W @ W)


def stiff(b, t, beta):
    A = E * b * t**3 / 12
    B = E * t * b**3 / 12
    C = G * beta * b * t**3
    return A, B, C


def fd_hessian(f, n, eps):
    """Central FD Hessian of scalar f: R^n -> R at 0."""
    H = np.zeros((n, n))
    I = np.eye(n) * eps
    f0 = f(np.zeros(n))
    for i in range(n):
        H[i, i] = (f(I[i]) - 2 * f0 + f(-I[i])) / eps**2
        for j in range(i + 1, n):
            H[i, j] = H[j, i] = (f(I[i] + I[j]) - f(I[i] - I[j]) - f(-I[i] + I[j]) + f(-I[i] - I[j])) / (4 * eps**2)
    return H


def fd_grad(f, n, eps):
    I = np.eye(n) * eps
    return np.array([(f(I[i]) - f(-I[i])) / (2 * eps) for i in range(n)])


def fd_jac(F, n, eps):
    I = np.eye(n) * eps
    return np.array([(F(I[i]) - F(-I[i])) / (2 * eps) for i in range(n)]).T


class Rod:
    def __init__(self, b, t, beta, N, lam, eps=1e-4):
        self.A, self.B, self.C = stiff(b, t, beta)
        self.K = np.diag([self.C, self.A, self.B])
        self.N, self.h = N, L / N
        self.kap = lam * 2 * np.pi / L
        self.M = self.A * self.kap      # equilibrium moment: M = lambda 2 pi E I_w / L
        self.b, self.t = b, t
        h, kap = self.h, self.kap
        Q0 = Ry(-kap * h)               # relative rotation of each link
        K = self.K

        def link(x):                    # x = (eta_a, eta_b)
            v = logm(expm(-x[:3]) @ Q0 @ expm(x[3:]))
            return 0.5 / h * v @ K @ v

        self.link = link
        self.R0N = Ry(-kap * L)
        d0 = self.R0N[:, 2]
        self.theta0 = kap * L

        def theta(d):                   # unwrapped atan2(-d_x, d_z) about the arc's tip value
            # rotate d by +kap L about y to bring d0 to e_z, then atan2
            dd = Ry(kap * L) @ d
            return self.theta0 + np.arctan2(-dd[0], dd[2])

        self.theta = theta

        def Vload(eta):
            d = self.R0N @ expm(eta) @ np.array([0, 0, 1.0])
            return -self.M * theta(d)

        self.Vload = Vload
        self.Hl = fd_hessian(link, 6, eps)
        self.gl = fd_grad(link, 6, eps)
        self.HV = fd_hessian(Vload, 3, eps)
        self.gV = fd_grad(Vload, 3, eps)

    def assemble(self, with_load=True):
        N = self.N
        n = 3 * N                       # dofs: eta_1..eta_N (eta_0 clamped)
        H = np.zeros((n, n))
        g = np.zeros(n)
        for k in range(1, N + 1):       # link k between frame k-1 and k
            ia = 3 * (k - 2)            # dofs of frame k-1 (absent if k-1 == 0)
            ib = 3 * (k - 1)
            if k == 1:
                H[ib:ib + 3, ib:ib + 3] += self.Hl[3:, 3:]
                g[ib:ib + 3] += self.gl[3:]
            else:
                idx = np.r_[ia:ia + 3, ib:ib + 3]
                H[np.ix_(idx, idx)] += self.Hl
                g[idx] += self.gl
        if with_load:
            H[-3:, -3:] += self.HV
            g[-3:] += self.gV
        return H, g

    def split(self, H):
        oop = np.sort(np.r_[0:3 * self.N:3, 2:3 * self.N:3])
        inp = np.r_[1:3 * self.N:3]
        return H[np.ix_(oop, oop)], H[np.ix_(inp, inp)], H[np.ix_(oop, inp)]

    # ---------- dynamics ----------
    def mass(self):
        N, h, b, t = self.N, self.h, self.b, self.t
        n = 3 * N
        Iw, Il = b * t**3 / 12, t * b**3 / 12
        Mm = np.zeros((n, n))
        for k in range(N):
            Mm[3 * k:3 * k + 3, 3 * k:3 * k + 3] += RHO * h * np.diag([Iw + Il, Iw, Il])
        # translational: nodes x_k = sum_{i<=k} h t_i ; delta t_i = R0_i (eta_i x e1) = -R0_i hat(e1) eta_i
        m = RHO * b * t * h
        e1 = np.array([1.0, 0, 0])
        Gk = np.zeros((3, n))
        for k in range(1, N + 1):
            R0k = Ry(-self.kap * k * h)
            Gk[:, 3 * (k - 1):3 * k] = -h * R0k @ hat(e1)
            mk = m if k < N else m / 2
            Mm += mk * Gk.T @ Gk
        return Mm

    def dead_load_stiffness(self, eps=1e-5):
        m = np.array([0.0, -self.M, 0.0])

        def Q(eta):
            R = self.R0N @ expm(eta)
            return Jr(eta).T @ R.T @ m

        return -fd_jac(Q, 3, eps), Q(np.zeros(3))

    def tau_load_force(self, eta):
        """generalised force from the given torque formula tau(d) (spatial), mapped to eta."""
        R = self.R0N @ expm(eta)
        d = R[:, 2]
        dx, dy, dz = d
        s = dx * dx + dz * dz
        tau = self.M * np.array([dy * dx, -s, dy * dz]) / s
        return Jr(eta).T @ R.T @ tau


def crit_lambda_discrete(b, t, beta, N, which="oop", lo=0.02, hi=1.6, nscan=80):
    def f(lam):
        r = Rod(b, t, beta, N, lam)
        H, _ = r.assemble()
        Ho, Hi, _ = r.split(H)
        Hx = Ho if which == "oop" else Hi
        # scale-free indicator: smallest eigenvalue of D^-1/2 H D^-1/2
        dsq = 1 / np.sqrt(np.abs(np.diag(Hx)))
        return np.linalg.eigvalsh(Hx * dsq[:, None] * dsq[None, :])[0]

    lams = np.linspace(lo, hi, nscan)
    vals = [f(l) for l in lams]
    for i in range(len(lams) - 1):
        if vals[i] > 0 and vals[i + 1] <= 0:
            return brentq(f, lams[i], lams[i + 1], xtol=1e-6), lams, vals
    return None, lams, vals


# ---------- continuum second variation, P1 FEM ----------
def continuum_form(b, t, beta, lam, ne):
    """delta^2 E = int 1/2 C (e1' + k e3)^2 + 1/2 B (e3' - k e1)^2 - A k^2/2 (e1^2 + e3^2) - A k e3 e1' ds
       (e1 = twist, e3 = lateral rotation, body components; e(0) = 0; no boundary term: the
        load's M/2 e1 e3 term cancels the boundary term from integrating the stress term by parts).
       Sign convention here: kappa > 0 rotation about +e2 (equivalent by symmetry)."""
    A, B, C = stiff(b, t, beta)
    k = lam * 2 * np.pi / L
    he = L / ne
    # element matrices for P1: N1 = 1 - x/h, N2 = x/h
    Kd = np.array([[1, -1], [-1, 1]]) / he          # int N' N'
    Mm = he / 6 * np.array([[2, 1], [1, 2]])         # int N N
    Cm = np.array([[-0.5, 0.5], [-0.5, 0.5]])        # int N_i N_j'
    n = 2 * (ne + 1)
    H = np.zeros((n, n))
    for e in range(ne):
        i1 = [2 * e, 2 * e + 2]        # e1 dofs
        i3 = [2 * e + 1, 2 * e + 3]    # e3 dofs
        # 1/2 C (e1'^2 + 2k e1' e3 + k^2 e3^2)
        blk = np.zeros((4, 4))
        idx = i1 + i3
        E11 = C * Kd + B * k**2 * Mm - A * k**2 * Mm
        E33 = B * Kd + C * k**2 * Mm - A * k**2 * Mm
        # cross terms: C k e1' e3  - B k e3' e1  - A k e3 e1'
        # quadratic form x^T H x /2: coefficient of e1_i e3_j
        X13 = C * k * Cm.T - B * k * Cm - A * k * Cm.T   # [i (e1), j (e3)]
        # int e1' e3 -> sum_ij e1_i e3_j int N_i' N_j = Cm.T[i,j]; int e3' e1 -> e1_i e3_j int N_i N_j' = Cm[i,j]
        blk[:2, :2] = E11
        blk[2:, 2:] = E33
        blk[:2, 2:] = X13
        blk[2:, :2] = X13.T
        H[np.ix_(idx, idx)] += blk
    H = H[2:, 2:]   # clamp
    return H


def crit_lambda_continuum(b, t, beta, ne, lo=0.02, hi=1.6, nscan=80):
    def f(lam):
        H = continuum_form(b, t, beta, lam, ne)
        dsq = 1 / np.sqrt(np.abs(np.diag(H)))
        return np.linalg.eigvalsh(H * dsq[:, None] * dsq[None, :])[0]

    lams = np.linspace(lo, hi, nscan)
    vals = [f(l) for l in lams]
    for i in range(len(lams) - 1):
        if vals[i] > 0 and vals[i + 1] <= 0:
            return brentq(f, lams[i], lams[i + 1], xtol=1e-6)
    return None


CASES = [("b/t=2 ", 1.0, 0.5, 0.229), ("b/t=4 ", 1.0, 0.25, 0.281), ("b/t=10", 1.0, 0.1, 0.312)]

if __name__ == "__main__":
    import sys
    np.set_printoptions(precision=5, linewidth=150, suppress=False)
    # --- tip-load second-order form & torque-formula check
    r = Rod(1.0, 0.25, 0.281, 48, 0.8)
    print("M =", r.M)
    print("grad V at arc tip (expect (0, M, 0)):", r.gV)
    print("Hess V / M (body rotation vector of tip frame):\n", r.HV / r.M)
    Qtau = r.tau_load_force(np.zeros(3))
    Jtau = fd_jac(r.tau_load_force, 3, 1e-5)
    print("gen. force from tau formula:", Qtau, " -dQ/deta / M:\n", -Jtau / r.M)
    KLd, Qd = r.dead_load_stiffness()
    print("dead moment: gen force", Qd, " load stiffness -dQ/deta / M:\n", KLd / r.M)
    # --- equilibrium check
    H, g = r.assemble()
    print("max |gradient| at planar arc (relative to M):", np.abs(g).max() / r.M)
    Ho, Hi, Hx = r.split(H)
    print("max |coupling oop-inplane| / max|H|:", np.abs(Hx).max() / np.abs(H).max())
    # --- sanity (1): straight rod, no load
    r0 = Rod(1.0, 0.25, 0.281, 48, 0.0)
    H0, g0 = r0.assemble(with_load=False)
    print("straight rod unloaded: min eig H =", np.linalg.eigvalsh(H0)[0], " (A/(h L^2)-ish scale)")
    sys.stdout.flush()
    # --- the critical load fraction per cross-section (out-of-plane), N = 48 and the continuum form
    for name, b, t, beta in CASES:
        lc = crit_lambda_discrete(b, t, beta, 48, "oop", hi=2.5, nscan=60)[0]
        print(name, "lambda_c (out of plane): discrete N=48", lc, " continuum FE 200:",
              crit_lambda_continuum(b, t, beta, 200, hi=2.5, nscan=60), flush=True)
