#!/usr/bin/env python3
"""Does the closed valve hold a diastole? Reads a run of scripts/validate_diastole.sh (the physio scene with the
LV inlet held at a constant diastolic pressure) and prints, every 10 ms:

    fluid particles, volume_ratio (diagnostics.csv), flow through the annulus and through the aortic outlet
    [ml/s] (positive towards the aorta), the aorta probe's pressure and the Windkessel's pressure at the outlet
    [mmHg above the 2 kPa background], and the fluid particles inside a wall (scripts/wall_leak.py's wall
    fraction above 0.8) in the VTK frame of that time, if there is one.

Then a summary over the window from --from (default 30 ms, after the start-up's acoustic transient) to --to
(default the end):
the fluid particles' growth per 10 ms, the mean flows through the annulus and the aortic outlet (a closed valve
that holds: both near 0, and equal), the mean of the aorta probe's pressure less the Windkessel's (the outlet's
push on the fluid: near 0 when the fluid's density answers the volume it is given), and the largest number of
particles inside a wall.

usage: scripts/diastole.py RUN_DIR [--from T] [--to T]   (numpy; Debian's python3-numpy)
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import study_report  # noqa: E402 (same folder: its .vtp reader)
import vtk_run  # noqa: E402
import wall_leak  # noqa: E402

BACKGROUND = 2000.0  # Pa: the physio scene's 0 mmHg
MMHG = 133.322


def table(path):
    rows = study_report.read_csv_rows(path)
    data = np.array([[float(v) for v in r] for r in rows[1:] if r])
    return {k: data[:, i] for i, k in enumerate(rows[0])}


def walls_inside(run_dir, scene):
    """Time of each VTK frame -> fluid particles inside a wall."""
    dx = scene["resolution"]["spacing"]
    h = scene["resolution"].get("smoothing_ratio", 1.3) * dx
    fluid = vtk_run.bodies_of_type(scene, "fluid")
    walls = vtk_run.bodies_of_type(scene, "wall")
    out = {}
    for t, path in vtk_run.frame_times(run_dir):
        d = {k: np.asarray(v) for k, v in study_report.read_vtp(path).items()}
        body = d["body"].astype(np.int64)
        fl = np.isin(body, fluid)
        frac = wall_leak.wall_fraction(d["Points"][fl], d["Points"][np.isin(body, walls)], dx, h)
        out[round(t, 6)] = int((frac > 0.8).sum())
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--from", dest="t0", type=float, default=0.03)
    ap.add_argument("--to", dest="t1", type=float, default=1e30)
    a = ap.parse_args()
    scene = vtk_run.run_scene(a.run_dir)
    diag = table(os.path.join(a.run_dir, "diagnostics.csv"))
    probes = table(os.path.join(a.run_dir, "probes.csv"))
    need = ["q_annulus", "p_aorta", "balance.aorta.flow", "balance.aorta.pressure"]
    missing = [k for k in need if k not in probes]
    if missing:
        sys.exit(f"{a.run_dir}/probes.csv: no column {', '.join(missing)} (not a physio-scene run?)")
    inside = walls_inside(a.run_dir, scene)
    t = probes["time"]
    mm = lambda p: (p - BACKGROUND) / MMHG  # noqa: E731
    print("t [s]   fluid  volume_ratio  q_annulus  q_aorta [ml/s]  p_aorta  p_windkessel [mmHg]  in_wall")
    for k in range(len(t)):
        if abs(t[k] * 100 - round(t[k] * 100)) > 1e-6:
            continue
        d = int(np.argmin(np.abs(diag["time"] - t[k])))
        wall = inside.get(round(t[k], 6), "")
        print(f"{t[k]:.3f}  {int(diag['fluid'][d]):6d}  {diag['volume_ratio'][d]:.4f}  "
              f"{probes['q_annulus'][k] * 1e6:9.1f}  {probes['balance.aorta.flow'][k] * 1e6:9.1f}  "
              f"{mm(probes['p_aorta'][k]):8.1f}  {mm(probes['balance.aorta.pressure'][k]):8.1f}  {wall}")
    w = (t >= a.t0 - 1e-9) & (t <= a.t1 + 1e-9)
    dw = (diag["time"] >= a.t0 - 1e-9) & (diag["time"] <= a.t1 + 1e-9)
    if w.sum() < 2 or dw.sum() < 2:
        sys.exit(f"the run ends before {a.t0} s")
    n = diag["fluid"][dw]
    span = diag["time"][dw][-1] - diag["time"][dw][0]
    growth = 100.0 * (n[-1] / n[0] - 1.0) * 0.01 / span
    gap = mm(probes["p_aorta"][w]) - mm(probes["balance.aorta.pressure"][w])
    print(f"over {t[w][0]:.3f}-{t[w][-1]:.3f} s:")
    print(f"  fluid particles {int(n[0])} -> {int(n[-1])}: {growth:+.2f} % per 10 ms")
    print(f"  mean flow: annulus {probes['q_annulus'][w].mean() * 1e6:+.1f} ml/s, aortic outlet "
          f"{probes['balance.aorta.flow'][w].mean() * 1e6:+.1f} ml/s")
    print(f"  aorta probe less Windkessel: mean {gap.mean():+.1f} mmHg (last 10 ms {gap[-10:].mean():+.1f})")
    if inside:
        seen = {k: v for k, v in inside.items() if k <= a.t1 + 1e-9}
        print(f"  fluid particles inside a wall: at most {max(seen.values())} (last frame {seen[max(seen)]})")


if __name__ == "__main__":
    main()
