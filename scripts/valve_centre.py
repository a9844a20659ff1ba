#!/usr/bin/env python3
"""The closed valve's centre and the jet, frame by frame, from an aortic run's VTK output (aortasph run --vtk).

usage: scripts/valve_centre.py RUN_DIR [--from T0] [--to T1] [--every N] [--jet] [--crossings]

For each frame (every Nth of those in [T0, T1]), about the y axis (the aortic scenes' valve axis):
  - tips: each leaflet's innermost particle (distance from the axis r and height y) — where the free edges meet;
  - between: blood particles with particles of two different leaflets within 1.2 spacings on opposite sides
    (the directions to the two nearest have a cosine below -0.3), their number and speeds (largest, mean);
  - centre flux: the volume flux of the blood at r < 2.5 mm across the band 4 mm < y < 8 mm, sum of
    V_i v_y,i / (4 mm) with V_i = m / rho_i (m = rho0 dx^3) [ml/s; negative: towards the ventricle];
  - with --jet: the largest speed of the Shepard kernel average of the velocity, sum_j V_j v_j W_ij /
    sum_j V_j W_ij over the blood within 2h (the cubic spline of paper eq. (5) at the run's h), at the blood's
    particles in the box |x|, |z| < 15 mm, -2 mm < y < 20 mm (the physio scene's jet probe region), beside the
    fastest particle's speed there: what `max_speed` probes read with and without "smoothed" (docs/scenes.md).

With --crossings, at the end: the blood that crossed the closed valve between the frames, by particle id. In
each frame a blood particle is on the aortic side when it is more than 0.4 spacings above every leaflet particle
within 1.2 spacings of its vertical line (horizontal distance), on the ventricular side when it is more than 0.4
spacings below all of them (neither: beside a sheet or none near); a particle seen on one side and in a later
frame on the other crossed. Printed: how many crossed each way, their volume (m / rho0 each) [ml] and rate over
the frames' span [ml/s], where each crossing one was last seen on its first side (distance from the axis,
height, and the leaflet whose sector it was over) and where it was first seen on the other. With frames closer
than the time blood takes to pass the leaflets (10 ms frames at 2-5 m/s are not) the path in between shows.
Stop 59 found that the leak of physio55n's diastoles is blood passing down past the leaflet tips at the axis
(1324 particles over 2.20-2.39 s: 7.0 ml/s, the annulus flow probe's 6-8 ml/s).

Stop 57 (docs/validation.md) found the diastolic leak of physio55n this way: 3-5 blood particles between the
leaflet tips at the axis at 2-5 m/s in every diastolic frame, a channel about one spacing wide.

Bodies come from run.json: fluid bodies are the blood, shell bodies the leaflets. Reads the ASCII .vtp files
aortasph writes; needs numpy only.
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
    """Paper eq. (5), 3-D: sigma = 1 / (pi h^3), q = r / h, support 2h."""
    q = r / h
    w = np.where(q < 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, np.where(q < 2.0, 0.25 * (2.0 - q) ** 3, 0.0))
    return w / (math.pi * h**3)


def nearest(xq, xs, reach):
    """Distance from each row of xq to its nearest row of xs within reach (inf beyond) and that row's index."""
    best = np.full(len(xq), np.inf)
    arg = np.zeros(len(xq), dtype=np.int64)
    for rows, j in vtk_run.cell_pairs(xq, xs, reach):
        d = np.linalg.norm(xs[j] - xq[rows], axis=1)
        better = d < best[rows]
        best[rows[better]] = d[better]
        arg[rows[better]] = j[better]
    return best, arg


def smoothed_max(x, v, vol, box, h):
    """Largest |Shepard average of v| at the rows of x inside box, over rows within 2h; and the largest |v|."""
    inside = np.all((x >= box[0]) & (x <= box[1]), axis=1)
    q = np.nonzero(inside)[0]
    if len(q) == 0:
        return float("nan"), float("nan")
    vw = np.zeros((len(q), 3))
    w = np.zeros(len(q))
    for rows, j in vtk_run.cell_pairs(x[q], x, 2.0 * h):
        wj = cubic_spline(np.linalg.norm(x[j] - x[q[rows]], axis=1), h) * vol[j]
        np.add.at(vw, rows, wj[:, None] * v[j])
        np.add.at(w, rows, wj)
    return float(np.max(np.linalg.norm(vw / w[:, None], axis=1))), float(np.max(np.linalg.norm(v[q], axis=1)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--from", dest="t0", type=float, default=-math.inf)
    ap.add_argument("--to", dest="t1", type=float, default=math.inf)
    ap.add_argument("--every", type=int, default=1)
    ap.add_argument("--jet", action="store_true")
    ap.add_argument("--crossings", action="store_true")
    a = ap.parse_args()
    if a.every < 1:
        sys.exit("--every: expected 1 or more")
    scene = vtk_run.run_scene(a.run_dir)
    fluid = vtk_run.bodies_of_type(scene, "fluid")
    leaflets = vtk_run.bodies_of_type(scene, "shell")
    if not fluid or len(leaflets) < 2:
        sys.exit(f"{a.run_dir}: needs a fluid body and two or more shell bodies (leaflets)")
    dx = scene["resolution"]["spacing"]
    h = scene["resolution"].get("smoothing_ratio", 1.3) * dx
    rho0 = scene["materials"][scene["bodies"][fluid[0]]["material"]]["density"]
    box = (np.array([-0.015, -0.002, -0.015]), np.array([0.015, 0.02, 0.015]))
    frames = [f for f in vtk_run.frame_times(a.run_dir) if a.t0 - 1e-9 <= f[0] <= a.t1 + 1e-9][:: a.every]
    if not frames:
        sys.exit("no frame in the interval")
    seen = {}  # --crossings: blood particle id -> [(frame, side, position)] where the side is +1 or -1
    for t, path in frames:
        d = {k: np.asarray(val) for k, val in study_report.read_vtp(path).items()}
        x, body, v, rho = d["Points"], d["body"].astype(int), d["velocity"], d["density"]
        blood = np.isin(body, fluid)
        if a.crossings:
            for pid, sd, xi in zip(*sides(x, body, d["id"].astype(np.int64), blood, np.isin(body, leaflets), dx)):
                seen.setdefault(pid, []).append((t, sd, xi))
        r = np.hypot(x[:, 0], x[:, 2])
        tips = []
        for lb in leaflets:
            k = np.nonzero(body == lb)[0]
            i = k[np.argmin(r[k])]
            tips.append(f"{r[i] * 1e3:.2f}/{x[i, 1] * 1e3:.1f}")
        # Blood near the leaflets: nearest particle of each leaflet within 1.2 dx.
        near = np.nonzero(blood & (r < 0.016))[0]
        dist = np.full((len(near), len(leaflets)), np.inf)
        vec = np.zeros((len(near), len(leaflets), 3))
        for c, lb in enumerate(leaflets):
            k = np.nonzero(body == lb)[0]
            dd, j = nearest(x[near], x[k], 1.2 * dx)
            ok = np.isfinite(dd)
            dist[ok, c] = dd[ok]
            vec[ok, c] = x[k[j[ok]]] - x[near[ok]]
        order = np.argsort(dist, axis=1)
        two = np.nonzero(np.take_along_axis(dist, order, axis=1)[:, 1] < 1.2 * dx)[0]
        between = []
        for s in two:
            va, vb = vec[s, order[s, 0]], vec[s, order[s, 1]]
            if va.dot(vb) < -0.3 * np.linalg.norm(va) * np.linalg.norm(vb):
                between.append(near[s])
        sp = np.linalg.norm(v[between], axis=1) if between else np.zeros(0)
        vol = rho0 * dx**3 / rho
        band = blood & (r < 0.0025) & (x[:, 1] > 0.004) & (x[:, 1] < 0.008)
        flux = float(np.sum(vol[band] * v[band, 1]) / 0.004 * 1e6)
        line = (f"t {t:.3f} s  tips r/y [mm] {' '.join(tips)}  between {len(between)} "
                f"(max {sp.max() if len(sp) else 0:.2f}, mean {sp.mean() if len(sp) else 0:.2f} m/s)  "
                f"centre flux {flux:+.1f} ml/s")
        if a.jet:
            b = np.nonzero(blood)[0]
            sm, raw = smoothed_max(x[b], v[b], vol[b], box, h)
            line += f"  jet smoothed {sm:.2f} / fastest {raw:.2f} m/s"
        print(line)
    if a.crossings:
        report_crossings(seen, frames, scene, dx)


def sides(x, body, ids, blood, leaf, dx):
    """The blood particles on either side of the leaflets: (ids, side +1 aortic / -1 ventricular, positions)."""
    xb, xl = x[blood], x[leaf]
    flat = np.array([1.0, 0.0, 1.0])
    lo = np.full(len(xb), np.inf)
    hi = np.full(len(xb), -np.inf)
    for rows, j in vtk_run.cell_pairs(xb * flat, xl * flat, 1.2 * dx):
        ok = np.linalg.norm((xl[j] - xb[rows]) * flat, axis=1) < 1.2 * dx
        np.minimum.at(lo, rows[ok], xl[j[ok], 1])
        np.maximum.at(hi, rows[ok], xl[j[ok], 1])
    side = np.where(xb[:, 1] > hi + 0.4 * dx, 1, np.where(xb[:, 1] < lo - 0.4 * dx, -1, 0))
    side[~np.isfinite(lo)] = 0
    keep = side != 0
    return ids[blood][keep], side[keep], xb[keep]


def report_crossings(seen, frames, scene, dx):
    """Prints the blood that changed sides between the frames (see --crossings)."""
    span = frames[-1][0] - frames[0][0]
    for frm, name in ((1, "aortic -> ventricular"), (-1, "ventricular -> aortic")):
        went = []
        for h in seen.values():
            last = None
            for t, sd, xi in h:
                if sd == frm:
                    last = xi
                elif last is not None:
                    went.append((last, xi))
                    break
        ml = len(went) * dx**3 * 1e6  # m / rho0 = dx^3 at rest
        line = f"crossed {name}: {len(went)} particles, {ml:.2f} ml"
        if span > 0:
            line += f", {ml / span:.2f} ml/s over {span:.3f} s"
        print(line)
        if not went:
            continue
        a = np.array([w[0] for w in went])
        b = np.array([w[1] for w in went])
        theta = np.degrees(np.arctan2(-a[:, 2], a[:, 0])) % 360.0
        # Leaflet k's sector runs from commissure k to commissure k + 1.
        sector = np.argmin((theta[:, None] - np.array(scene_commissures(scene))[None, :]) % 360.0, axis=1)
        over = np.bincount(sector, minlength=3)
        pct = lambda v: " / ".join(f"{q * 1e3:.1f}" for q in np.percentile(v, [10, 50, 90]))
        print(f"  last on the first side: r {pct(np.hypot(a[:, 0], a[:, 2]))} mm, y {pct(a[:, 1])} mm (10/50/90 %); "
              f"over leaflet sectors {' '.join(str(n) for n in over)}")
        print(f"  first on the other side: r {pct(np.hypot(b[:, 0], b[:, 2]))} mm, y {pct(b[:, 1])} mm")


def scene_commissures(scene):
    """The commissure angles [degrees] of the scene's aortic root (default 0, 120, 240)."""
    root = scene.get("aortic_root", {})
    return list(root.get("commissure_angles", [0.0, 120.0, 240.0]))


if __name__ == "__main__":
    main()
