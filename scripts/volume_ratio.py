#!/usr/bin/env python3
"""Does the fluid fill the volume its density says? From a run's VTK frames (aortasph run --vtk).

usage: scripts/volume_ratio.py RUN_DIR --frames N [N ...] [--bins Y0,Y1,...] [--near-sheet]

For each fluid particle away from the open ends it takes the particle's Voronoi cell (scipy.spatial.Voronoi
over every particle of the frame: fluid, walls, shells) and prints, per axial bin (y in mm; default the aortic
scenes' LVOT, valve, sinuses and aorta: -11,-6,0,6,12,18,24,30), the median of

    V_voronoi * rho / m0,    m0 = rho0 dx^3 (the fluid's particle mass),

the particle's geometric volume over the volume its mass and continuity density (paper eq. 12) give it. It is
1 on the initial lattice and stays near 1 while the continuity density follows the particles; above 1 the
particles stand farther apart than their densities say (the pressure does not see the thinning), below 1
closer. Cells that are open or reach more than 3 dx from their particle (a gap, an open end) are skipped.

--near-sheet also bins the particles by their distance to the nearest shell particle and to the nearest wall
particle (the cells of fluid within 1 mm of a sheet are cut by the sheet's own particles, so read that bin
as geometry, not thinning). Stop 50 used it to find the volume that particle shifting created beside the
valve's leaflets (docs/validation.md, "Stop 50"). Needs numpy and scipy.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402 (same folder: its .vtp reader)
import vtk_run  # noqa: E402


def ratios(run_dir, frame, scene, y_lo, y_hi):
    """Indices of the measured fluid particles, their V_voronoi rho / m0, and the frame's arrays."""
    from scipy.spatial import ConvexHull, Voronoi

    dx = scene["resolution"]["spacing"]
    rho0 = {k: scene["materials"][b["material"]].get("density") for k, b in enumerate(scene["bodies"])}
    fluid = vtk_run.bodies_of_type(scene, "fluid")
    path = os.path.join(run_dir, "vtk", f"particles_{frame:05d}.vtp")
    if not os.path.exists(path):
        sys.exit(f"{path}: no such frame")
    d = {k: np.asarray(v) for k, v in study_report.read_vtp(path).items()}
    x, body = d["Points"], d["body"].astype(int)
    y = x[:, 1] * 1e3
    sel = np.where((y > y_lo - 5) & (y < y_hi + 5))[0]  # the cells of the measured ones are closed by these
    vor = Voronoi(x[sel])
    idx, ratio = [], []
    for k, i in enumerate(sel):
        if body[i] not in fluid or not (y_lo <= y[i] < y_hi):
            continue
        region = vor.regions[vor.point_region[k]]
        if -1 in region or not region:
            continue
        corners = vor.vertices[region]
        if np.abs(corners - x[i]).max() > 3 * dx:
            continue
        idx.append(i)
        ratio.append(ConvexHull(corners).volume * d["density"][i] / (rho0[body[i]] * dx**3))
    return np.array(idx, dtype=int), np.array(ratio), d


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--frames", type=int, nargs="+", required=True, help="frame numbers (particles_N.vtp)")
    ap.add_argument("--bins", default="-11,-6,0,6,12,18,24,30", help="y bin edges [mm]")
    ap.add_argument("--near-sheet", action="store_true")
    a = ap.parse_args()
    try:
        edges = [float(v) for v in a.bins.split(",")]
    except ValueError:
        sys.exit(f"--bins {a.bins}: expected numbers separated by commas")
    if len(edges) < 2 or any(b <= c for c, b in zip(edges, edges[1:])):
        sys.exit(f"--bins {a.bins}: expected at least two increasing edges")
    scene = vtk_run.run_scene(a.run_dir)
    for frame in a.frames:
        idx, ratio, d = ratios(a.run_dir, frame, scene, edges[0], edges[-1])
        y = d["Points"][idx, 1] * 1e3
        cols = []
        for y0, y1 in zip(edges, edges[1:]):
            s = (y >= y0) & (y < y1)
            cols.append(f"{y0:g}..{y1:g}: {np.median(ratio[s]):.3f} ({int(s.sum())})" if s.any() else f"{y0:g}..{y1:g}: -")
        print(f"frame {frame}: median V_voronoi rho / m0 by y [mm]: " + "  ".join(cols))
        if not a.near_sheet:
            continue
        from scipy.spatial import cKDTree

        x = d["Points"]
        body = d["body"].astype(int)
        shell = np.isin(body, vtk_run.bodies_of_type(scene, "shell"))
        wall = np.isin(body, vtk_run.bodies_of_type(scene, "wall"))
        if not shell.any() or not wall.any():
            sys.exit(f"{a.run_dir}: --near-sheet needs shell and wall bodies")
        ds = cKDTree(x[shell]).query(x[idx])[0] * 1e3
        dw = cKDTree(x[wall]).query(x[idx])[0] * 1e3
        for lo, hi in [(0, 1), (1, 2), (2, 3), (3, 5), (5, 8), (8, np.inf)]:
            for wlo, whi in [(0, 2.5), (2.5, np.inf)]:
                s = (ds >= lo) & (ds < hi) & (dw >= wlo) & (dw < whi)
                if s.sum() >= 20:
                    print(f"  sheet {lo:g}-{hi:g} mm, wall {wlo:g}-{whi:g} mm: {np.median(ratio[s]):.3f} ({int(s.sum())})")


if __name__ == "__main__":
    main()
