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
import json
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402 (same folder: its .vtp reader)


def nearest(x, dx):
    """Distance from each row of x to its nearest other row, capped at dx (cells of side dx, 27 round each)."""
    lo = x.min(axis=0) - dx
    c = np.floor((x - lo) / dx).astype(np.int64)
    dims = c.max(axis=0) + 3

    def key(cc):
        return (cc[:, 0] * dims[1] + cc[:, 1]) * dims[2] + cc[:, 2]

    k = key(c)
    order = np.argsort(k, kind="stable")
    ks, xs = k[order], x[order]
    best = np.full(len(x), dx)
    for off in np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1])).T.reshape(-1, 3):
        kk = key(c + off)
        begin, end = np.searchsorted(ks, kk, "left"), np.searchsorted(ks, kk, "right")
        for n in range(int((end - begin).max(initial=0))):
            rows = np.where(begin + n < end)[0]
            j = begin[rows] + n
            d = np.linalg.norm(xs[j] - x[rows], axis=1)
            d[order[j] == rows] = dx  # not itself
            best[rows] = np.minimum(best[rows], d)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--slab", nargs="*", default=["-12:-2", "18:30"])
    ap.add_argument("--every", type=int, default=1, help="every N-th frame")
    ap.add_argument("--fluid-body", type=int, nargs="*")
    ap.add_argument("--axis-radius", type=float, default=8.0, help="core radius [mm]")
    a = ap.parse_args()
    try:
        run = json.load(open(os.path.join(a.run_dir, "run.json")))
    except (OSError, ValueError) as e:
        sys.exit(f"{a.run_dir}/run.json: {e}")
    scene = run["scene"]
    dx = scene["resolution"]["spacing"]
    mats = scene["materials"]
    fluid = a.fluid_body
    if fluid is None:
        fluid = [k for k, b in enumerate(scene["bodies"]) if mats[b["material"]]["type"] == "fluid"]
    slabs = []
    for s in a.slab:
        try:
            y0, y1 = (float(v) for v in s.split(":"))
        except ValueError:
            sys.exit(f"--slab {s}: expected Y0:Y1 in mm")
        slabs.append((y0, y1))
    vtk = os.path.join(a.run_dir, "vtk")
    try:
        frames = sorted(f for f in os.listdir(vtk) if f.endswith(".vtp"))
    except OSError as e:
        sys.exit(f"{vtk}: {e}")
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
            mean = lambda q, m: float(q[m].mean()) if m.any() else float("nan")  # noqa: E731
            cols.append(
                f"y {y0:g}..{y1:g}: n {int(s.sum())} rho {mean(rho, s):.1f} nn50 "
                f"{float(np.median(nn[s])) if s.any() else float('nan'):.2f} pairs {mean(nn < 0.5, s):.3f} "
                f"core {int(core.sum())} rim {int(rim.sum())} vy_core {mean(v[:, 1], core):+.3f} "
                f"vy_rim {mean(v[:, 1], rim):+.3f}"
            )
        label = times.get(f, f)
        print(f"{label}  " + "  |  ".join(cols))


if __name__ == "__main__":
    main()
