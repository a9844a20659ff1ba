#!/usr/bin/env python3
"""Fluid particles inside walls, frame by frame, from a run's VTK output (aortasph run --vtk).

usage: scripts/wall_leak.py RUN_DIR [--fluid-body N ...] [--wall-body N ...] [--threshold F] [--list K]

For each fluid particle, the wall fraction is the kernel-weighted volume of the wall particles in its
support, sum_w dx^3 W(|x - x_w|), with the cubic spline of paper eq. (5) at the run's h (run.json). In the
open fluid it is 0; beside a flat wall at its resting distance (dx/2 from the first layer's plane) about
0.37, up to about 0.72 in the aortic root's corners; a particle that has passed the first layer sits among wall
particles and has 0.8 or more. Particles over --threshold (default 0.8) are counted as inside a wall; the
--list K deepest of the last frame that has any are printed with their cylindrical coordinates about the
y axis (the aortic scenes' axis). Bodies are numbered as in the scene (VTK array "body"); by default the
fluid bodies are the fluid and every wall body is a wall.

Reads the ASCII .vtp files aortasph writes; needs numpy only (Debian's python3-numpy, which python3-matplotlib
of scripts/install-deps.sh brings).
"""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402 (same folder: its .vtp reader)
import vtk_run  # noqa: E402


def cubic_spline(r, h):
    """Paper eq. (5), 3-D: sigma = 1 / (pi h^3), q = r / h, support 2h. (jet_noise.py has the unnormalised
    shape, but importing it needs scipy.)"""
    q = r / h
    w = np.where(q < 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, np.where(q < 2.0, 0.25 * (2.0 - q) ** 3, 0.0))
    return w / (math.pi * h**3)


def wall_fraction(xf, xw, dx, h):
    """sum over wall particles within 2h of each row of xf of dx^3 W: cells of side 2h, the 27 round each."""
    frac = np.zeros(len(xf))
    for rows, j in vtk_run.cell_pairs(xf, xw, 2.0 * h):
        frac[rows] += dx**3 * cubic_spline(np.linalg.norm(xw[j] - xf[rows], axis=1), h)
    return frac


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--fluid-body", type=int, nargs="*")
    ap.add_argument("--wall-body", type=int, nargs="*")
    ap.add_argument("--threshold", type=float, default=0.8)
    ap.add_argument("--list", type=int, default=5)
    a = ap.parse_args()
    scene = vtk_run.run_scene(a.run_dir)
    dx = scene["resolution"]["spacing"]
    h = scene["resolution"].get("smoothing_ratio", 1.3) * dx
    fluid = a.fluid_body if a.fluid_body is not None else vtk_run.bodies_of_type(scene, "fluid")
    walls = a.wall_body if a.wall_body is not None else vtk_run.bodies_of_type(scene, "wall")
    if not fluid or not walls:
        sys.exit("no fluid or no wall body in the run's scene")
    vtk = os.path.join(a.run_dir, "vtk")
    frames = vtk_run.frames(a.run_dir)
    print(f"# dx {dx} m, h {h} m; fluid body {fluid}, wall bodies {walls}; inside: wall fraction > {a.threshold}")
    print("frame  fluid  inside  largest_fraction")
    last = None
    for f in frames:
        d = {k: np.asarray(v) for k, v in study_report.read_vtp(os.path.join(vtk, f)).items()}
        x, body = d["Points"], d["body"].astype(np.int64)
        fl = np.where(np.isin(body, fluid))[0]
        wl = np.isin(body, walls)
        frac = wall_fraction(x[fl], x[wl], dx, h)
        inside = frac > a.threshold
        print(f"{f}  {len(fl)}  {int(inside.sum())}  {frac.max():.3f}")
        if inside.any():
            last = (f, x[fl[inside]], frac[inside], d.get("id")[fl[inside]] if "id" in d else None,
                    d["density"][fl[inside]], d["pressure"][fl[inside]])
    if last and a.list > 0:
        f, xs, fr, ids, rho, p = last
        print(f"# deepest in {f}: id, r [mm], y [mm], theta [deg], wall fraction, density, pressure [Pa]")
        for k in np.argsort(-fr)[: a.list]:
            r = math.hypot(xs[k, 0], xs[k, 2]) * 1e3
            th = math.degrees(math.atan2(xs[k, 2], xs[k, 0]))
            pid = int(ids[k]) if ids is not None else -1
            print(f"{pid} {r:.2f} {xs[k, 1] * 1e3:.2f} {th:.1f} {fr[k]:.3f} {rho[k]:.1f} {p[k]:.0f}")


if __name__ == "__main__":
    main()
