#!/usr/bin/env python3
"""How the fluid's particles pack, frame by frame, from a run's VTK output (aortasph run --vtk).

usage: scripts/packing.py RUN_DIR [--slab Y0:Y1 ...] [--every N] [--fluid-body N ...] [--axis-radius R]

For each axial slab (y between Y0 and Y1, in mm; default the aortic scenes' LVOT -12:-2 and aorta 18:30)
and each frame it prints:
  - n: the fluid particles in the slab. In a rigid segment of tube at a nearly constant density n can only
    change by the fluid's compression (dp / (rho c0^2), under 1 % in the physio scene); more means particles
    packed closer than their densities say (the continuity density, paper eq. 12, does not see packing);
  - rho: their mean density (the continuity density when the scene integrates it);
  - nn50: the median distance to the nearest fluid particle, in spacings (1 on the initial lattice; about
    0.8-0.9 for a healthy disordered fluid), and pairs: the share closer than dx/2 (close pairs: the pairing
    instability of the cubic spline at large h / dx; Dehnen & Aly 2012, MNRAS 425:1068);
  - core / rim: the particles within --axis-radius (default 8 mm) of the y axis and those beyond it, and
    vy_core / vy_rim their mean axial velocity (a rim moving against a core at rest is flow along the wall).

Distances closer than one spacing are found exactly; the nearest neighbour of a particle with none within a
spacing counts as one spacing. Reads the ASCII .vtp files aortasph writes; needs numpy only.
"""
import argparse
import math
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402 (same folder: its .vtp reader)
import vtk_run  # noqa: E402


def nearest(x, dx):
    """Distance from each row of x to its nearest other row, capped at dx."""
    best = np.full(len(x), dx)
    for rows, j in vtk_run.cell_pairs(x, x, dx):
        d = np.linalg.norm(x[j] - x[rows], axis=1)
        d[j == rows] = dx  # not itself
        best[rows] = np.minimum(best[rows], d)
    return best


def mean(q, m):
    """Mean of q over the mask m (NaN where m is empty)."""
    return float(q[m].mean()) if m.any() else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--slab", nargs="*", default=["-12:-2", "18:30"])
    ap.add_argument("--every", type=int, default=1, help="every N-th frame")
    ap.add_argument("--fluid-body", type=int, nargs="*")
    ap.add_argument("--axis-radius", type=float, default=8.0, help="core radius [mm]")
    a = ap.parse_args()
    scene = vtk_run.run_scene(a.run_dir)
    dx = scene["resolution"]["spacing"]
    fluid = a.fluid_body if a.fluid_body is not None else vtk_run.bodies_of_type(scene, "fluid")
    slabs = []
    for s in a.slab:
        try:
            y0, y1 = (float(v) for v in s.split(":"))
        except ValueError:
            sys.exit(f"--slab {s}: expected Y0:Y1 in mm")
        slabs.append((y0, y1))
    vtk = os.path.join(a.run_dir, "vtk")
    frames = vtk_run.frames(a.run_dir)
    times = {}  # frame file -> "t = ... s", from the .pvd collection
    try:
        for m in re.finditer(r'timestep="([^"]+)"[^>]*file="([^"]+)"', open(os.path.join(vtk, "particles.pvd")).read()):
            times[os.path.basename(m.group(2))] = f"t = {float(m.group(1)):.4f} s"
    except OSError:
        pass
    for f in frames[:: a.every]:
        d = {k: np.asarray(v) for k, v in study_report.read_vtp(os.path.join(vtk, f)).items()}
        keep = np.isin(d["body"], fluid)
        x = d["Points"][keep]
        nn = nearest(x, dx) / dx
        xm = x * 1e3
        y, r = xm[:, 1], np.hypot(xm[:, 0], xm[:, 2])
        rho, v = d["density"][keep], d["velocity"][keep]
        cols = []
        for y0, y1 in slabs:
            s = (y >= y0) & (y < y1)
            core, rim = s & (r < a.axis_radius), s & (r >= a.axis_radius)
            cols.append(
                f"y {y0:g}..{y1:g}: n {int(s.sum())} rho {mean(rho, s):.1f} nn50 "
                f"{float(np.median(nn[s])) if s.any() else math.nan:.2f} pairs {mean(nn < 0.5, s):.3f} "
                f"core {int(core.sum())} rim {int(rim.sum())} vy_core {mean(v[:, 1], core):+.3f} "
                f"vy_rim {mean(v[:, 1], rim):+.3f}"
            )
        label = times.get(f, f)
        print(f"{label}  " + "  |  ".join(cols))


if __name__ == "__main__":
    main()
