#!/usr/bin/env python3
# An independent 2-D transport-velocity SPH (Adami, Hu & Adams 2013, J. Comput. Phys. 241:292, as PySPH cites
# its equations: eq. 7 the inter-particle-averaged pressure, eq. 8 the momentum equation with the extra stress
# A = rho v (v~ - v), eq. 13 the background-pressure acceleration, eqs. 14-16 the velocity-Verlet steps with
# v~ = v(t + dt/2) + (dt/2) a_b), quintic spline with h = dx, for the Taylor-Green vortex in a periodic unit
# square. Pure Python, no dependencies, slow (lambda/20: about a minute per half decay time): a reference
# for sim/fluid/transport_velocity.cpp, which is 3-D, cubic spline and Monaghan's pressure form (issue 20,
# docs/validation.md "Taylor-Green vortex"). Prints KE / exp(-4 nu k^2 t) at every tenth of T, the vortex
# mode's amplitude over the exact one and the rest of the kinetic energy (particle-scale noise) over KE(0).
# Environment: N (lambda/dx, 20), PB (p_b over rho0 c0^2, 1), NU (0.01), KER (quintic | cubic), HDX (h/dx),
# ATERM (1 the paper's A term, 0 none, 2 the non-conservative (v~ - v).grad v), PFORM (adami | monaghan),
# TEND (in T, 1), PERT (a uniform random offset of up to PERT/2 dx per axis at the start, 0).
import math, os, sys
N = int(os.environ.get('N', 20)); L = 1.0; U = 1.0; rho0 = 1.0; c0 = 10.0; p0 = c0*c0*rho0
nu = float(os.environ.get('NU', 0.01)); pbf = float(os.environ.get('PB', 1.0)); pb = pbf*p0
ker = os.environ.get('KER', 'quintic'); hdx = float(os.environ.get('HDX', 1.0 if ker == 'quintic' else 1.3))
aterm = int(os.environ.get('ATERM', 1)); pform = os.environ.get('PFORM', 'adami')
dx = L/N; h = hdx*dx; m = rho0*dx*dx
if ker == 'quintic':
    sup = 3*h; sig = 7/(478*math.pi*h*h)
    def W(r):
        q = r/h; f = 0.0
        if q < 3: f += (3-q)**5
        if q < 2: f -= 6*(2-q)**5
        if q < 1: f += 15*(1-q)**5
        return sig*f
    def dW(r):
        q = r/h; f = 0.0
        if q < 3: f -= 5*(3-q)**4
        if q < 2: f += 30*(2-q)**4
        if q < 1: f -= 75*(1-q)**4
        return sig*f/h
else:
    sup = 2*h; sig = 10/(7*math.pi*h*h)
    def W(r):
        q = r/h
        if q < 1: return sig*(1 - 1.5*q*q + 0.75*q**3)
        if q < 2: return sig*0.25*(2-q)**3
        return 0.0
    def dW(r):
        q = r/h
        if q < 1: return sig*(-3*q + 2.25*q*q)/h
        if q < 2: return -sig*0.75*(2-q)**2/h
        return 0.0
dt = min(0.25*h/(c0+U), 0.125*h*h/nu)
k = 2*math.pi/L
xs = []; ys = []; us = []; vs = []
pert = float(os.environ.get('PERT', 0)); import random; random.seed(1)
for i in range(N):
    for j in range(N):
        x = (i+0.5)*dx; y = (j+0.5)*dx
        if pert: x += pert*dx*(random.random()-0.5); y += pert*dx*(random.random()-0.5)
        xs.append(x % L); ys.append(y % L)
        us.append(U*math.sin(k*x)*math.cos(k*y)); vs.append(-U*math.cos(k*x)*math.sin(k*y))
n = len(xs)
nc = int(L/sup); cw = L/nc
def pairs():
    cells = {}
    for i in range(n):
        cells.setdefault((int(xs[i]/cw) % nc, int(ys[i]/cw) % nc), []).append(i)
    out = [[] for _ in range(n)]
    s2 = sup*sup
    for (cx, cy), lst in cells.items():
        nb = []
        for ddx in (-1, 0, 1):
            for ddy in (-1, 0, 1):
                nb += cells.get(((cx+ddx) % nc, (cy+ddy) % nc), [])
        for i in lst:
            xi = xs[i]; yi = ys[i]
            for j in nb:
                if j == i: continue
                rx = xi - xs[j]; ry = yi - ys[j]
                rx -= L*round(rx/L); ry -= L*round(ry/L)
                r2 = rx*rx + ry*ry
                if r2 < s2: out[i].append((j, rx, ry, math.sqrt(r2)))
    return out
W0 = W(0.0)
def evaluate(u, v, uh, vh):
    P = pairs()
    V = [0.0]*n; rho = [0.0]*n; p = [0.0]*n
    for i in range(n):
        s = W0
        for j, rx, ry, r in P[i]: s += W(r)
        V[i] = 1.0/s; rho[i] = m*s; p[i] = p0*(rho[i]/rho0 - 1.0)
    ax = [0.0]*n; ay = [0.0]*n; bx = [0.0]*n; by = [0.0]*n
    eps = 0.01*h*h
    for i in range(n):
        Vi2 = V[i]*V[i]; sx = sy = tx = ty = 0.0
        Axx = rho[i]*u[i]*(uh[i]-u[i]); Axy = rho[i]*u[i]*(vh[i]-v[i]); Ayx = rho[i]*v[i]*(uh[i]-u[i]); Ayy = rho[i]*v[i]*(vh[i]-v[i])
        for j, rx, ry, r in P[i]:
            g = dW(r)/r; gx = g*rx; gy = g*ry
            Vj2 = V[j]*V[j]; fac = (Vi2 + Vj2)/m
            if pform == 'adami':
                pij = (rho[j]*p[i] + rho[i]*p[j])/(rho[i]+rho[j]); sc = -pij*fac
            else:
                sc = -m*(p[i]/rho[i]**2 + p[j]/rho[j]**2)
            # viscosity (eta = rho nu, harmonic mean)
            ei = nu*rho[i]; ej = nu*rho[j]; eij = 2*ei*ej/(ei+ej)
            F = gx*rx + gy*ry
            vis = fac*eij*F/(r*r + eps)
            sx += sc*gx + vis*(u[i]-u[j]); sy += sc*gy + vis*(v[i]-v[j])
            if aterm == 2:
                dxi = uh[i]-u[i]; dyi = vh[i]-v[i]; dd = V[j]*(dxi*gx + dyi*gy)
                sx += dd*(u[j]-u[i]); sy += dd*(v[j]-v[i])
            elif aterm:
                Bxx = rho[j]*u[j]*(uh[j]-u[j]); Bxy = rho[j]*u[j]*(vh[j]-v[j]); Byx = rho[j]*v[j]*(uh[j]-u[j]); Byy = rho[j]*v[j]*(vh[j]-v[j])
                sx += fac*0.5*((Axx+Bxx)*gx + (Axy+Bxy)*gy); sy += fac*0.5*((Ayx+Byx)*gx + (Ayy+Byy)*gy)
            tx += -pb*fac*gx; ty += -pb*fac*gy
        ax[i] = sx; ay[i] = sy; bx[i] = tx; by[i] = ty
    return ax, ay, bx, by, rho, P
u = us[:]; v = vs[:]; uh = u[:]; vh = v[:]
ax, ay, bx, by, rho, P = evaluate(u, v, uh, vh)
rate = 4*nu*k*k; T = 1/rate
e0 = 0.5*m*sum(a*a + b*b for a, b in zip(u, v))
tend = float(os.environ.get('TEND', 1.0))*T
t = 0.0; nextout = 0.1*T; step = 0
print(f"N={N} n={n} dt={dt:.3g} T={T:.4f} ker={ker} h/dx={hdx} pb={pb} aterm={aterm} pform={pform}", flush=True)
while t < tend - 1e-12:
    for i in range(n):
        u[i] += 0.5*dt*ax[i]; v[i] += 0.5*dt*ay[i]
        uh[i] = u[i] + 0.5*dt*bx[i]; vh[i] = v[i] + 0.5*dt*by[i]
        xs[i] = (xs[i] + dt*uh[i]) % L; ys[i] = (ys[i] + dt*vh[i]) % L
    ax, ay, bx, by, rho, P = evaluate(u, v, uh, vh)
    for i in range(n):
        u[i] += 0.5*dt*ax[i]; v[i] += 0.5*dt*ay[i]
    t += dt; step += 1
    if t >= nextout - 1e-12:
        ke = 0.5*m*sum(a*a + b*b for a, b in zip(u, v))
        dmin = min((r for i in range(n) for (j, rx, ry, r) in P[i]), default=9)
        close = sum(1 for i in range(n) if min((r for (j, rx, ry, r) in P[i]), default=9) < 0.8*dx)/n
        rm = sum(rho)/n
        ph = [(math.sin(k*xs[i])*math.cos(k*ys[i]), -math.cos(k*xs[i])*math.sin(k*ys[i])) for i in range(n)]
        amp = sum(u[i]*ph[i][0] + v[i]*ph[i][1] for i in range(n))/sum(a*a + b*b for a, b in ph)
        kem = 0.5*m*amp*amp*sum(a*a + b*b for a, b in ph)
        print(f"  mode amp/exact={amp/U/math.exp(-0.5*rate*t):.4f} KEnoise/KE0={(ke-kem)/e0:.4f}", end=' ')
        print(f"t={t:.3f} ({t/T:.2f}T) KE/exact={ke/e0/math.exp(-rate*t):.4f} dmin/dx={dmin/dx:.3f} nn<0.8dx={close:.3f} rho_mean={rm:.4f} steps={step}", flush=True)
        nextout += 0.1*T
