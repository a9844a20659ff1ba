#!/usr/bin/env python3
"""Folds in a run's shell sheets, frame by frame, from its VTK output (aortasph run --vtk).

usage: scripts/sheet_folds.py RUN_DIR [--from T0] [--to T1] [--angle DEG] [--top N]

For each frame in [T0, T1] and each shell body: how many of its particles have a normal more than DEG degrees
(default 60) off the normal of one of their reference neighbours (the body's particles within 1.5 spacings of
them in the first frame, t = 0), and the N (default 3) with the largest such angle: their id, the angle, where
they were at t = 0 and where they are now (distance r from the y axis, the angle about it, atan2(-z, x) as the
aortic root's commissure angles, and the height y). A smooth sheet bent to a radius R turns its normal by about
1.5 dx / R between such neighbours (20 degrees at R = 4 dx); a fold or a crumpled edge turns it by 60-180.

Stop 61 found this way that the guard put-backs of a physio run with a central lunula (shell_putbacks.csv) were
at leaflet edges folded by 90-106 degrees, where the same valve closed without fluid had no angle over 45.

Bodies come from run.json (shell materials). Reads the ASCII .vtp files aortasph writes; needs numpy only.
"""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402 (same folder: its .vtp reader)
import vtk_run  # noqa: E402


def reference_neighbours(x0, reach):
    """Pairs (i, j), i != j, of the rows of x0 closer than reach."""
    pairs = []
    for rows, j in vtk_run.cell_pairs(x0, x0, reach):
        keep = (rows != j) & (np.linalg.norm(x0[rows] - x0[j], axis=1) < reach)
        pairs.append((rows[keep], j[keep]))
    if not pairs:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs])


def where(p):
    """'r R th TH y Y' in mm and degrees about the y axis."""
    r = math.hypot(p[0], p[2]) * 1e3
    th = math.degrees(math.atan2(-p[2], p[0])) % 360.0
    return f"r {r:5.2f} th {th:5.1f} y {p[1] * 1e3:6.2f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--from", dest="t0", type=float, default=-math.inf)
    ap.add_argument("--to", dest="t1", type=float, default=math.inf)
    ap.add_argument("--angle", type=float, default=60.0)
    ap.add_argument("--top", type=int, default=3)
    a = ap.parse_args()
    if not 0.0 < a.angle < 180.0:
        sys.exit("--angle: expected degrees in (0, 180)")
    if a.top < 0:
        sys.exit("--top: expected 0 or more")
    scene = vtk_run.run_scene(a.run_dir)
    sheets = vtk_run.bodies_of_type(scene, "shell")
    if not sheets:
        sys.exit(f"{a.run_dir}: no shell body in the scene")
    dx = scene["resolution"]["spacing"]
    frames = vtk_run.frame_times(a.run_dir)
    first = {k: np.asarray(v) for k, v in study_report.read_vtp(frames[0][1]).items()}
    ref = {}  # body -> (ids, positions at t = 0, neighbour pairs as indices into them)
    for b in sheets:
        s = np.where(first["body"].astype(int) == b)[0]
        x0 = first["Points"][s]
        ref[b] = (first["id"][s].astype(np.int64), x0, reference_neighbours(x0, 1.5 * dx))
    cos_limit = math.cos(math.radians(a.angle))
    for t, path in frames:
        if not a.t0 - 1e-9 <= t <= a.t1 + 1e-9:
            continue
        d = {k: np.asarray(v) for k, v in study_report.read_vtp(path).items()}
        print(f"t = {t:.4f} s")
        for b in sheets:
            ids, x0, (i, j) = ref[b]
            s = np.where(d["body"].astype(int) == b)[0]
            order = {int(pid): k for k, pid in enumerate(d["id"][s].astype(np.int64))}
            at = np.array([order.get(int(pid), -1) for pid in ids])
            ok = (at[i] >= 0) & (at[j] >= 0)
            n = d["normal"][s]
            cos = np.einsum("ij,ij->i", n[at[i[ok]]], n[at[j[ok]]])
            worst = np.ones(len(ids))
            np.minimum.at(worst, i[ok], cos)
            folded = np.where(worst < cos_limit)[0]
            name = scene["bodies"][b].get("name", str(b))
            print(f"  {name}: {len(folded)} of {len(ids)} particles more than {a.angle:g} deg off a neighbour")
            for k in np.argsort(worst)[: a.top]:
                ang = math.degrees(math.acos(max(-1.0, min(1.0, worst[k]))))
                now = d["Points"][s][at[k]] if at[k] >= 0 else None
                print(f"    id {ids[k]} {ang:5.1f} deg: at t = 0 {where(x0[k])}"
                      + (f", now {where(now)}" if now is not None else ""))


if __name__ == "__main__":
    main()
