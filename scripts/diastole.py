#!/usr/bin/env python3
"""Does the closed valve hold a diastole? Reads a run of scripts/validate_diastole.sh (the physio scene with the
LV inlet held at a constant diastolic pressure) and prints, every 10 ms:

    fluid particles, volume_ratio (diagnostics.csv), flow through the annulus and through the aortic outlet
    [ml/s] (positive towards the aorta), the aorta probe's pressure and the Windkessel's pressure at the outlet
    [mmHg above the 2 kPa background], and, from the VTK frame of that time if there is one, the fluid
    particles inside a wall (scripts/wall_leak.py's wall fraction above 0.8), the 99.9th percentile of the
    fluid's density error |rho / rho0 - 1| [%] and how many fluid particles are over 3 %.

Then a summary over the window from --from (default 30 ms, after the start-up's acoustic transient) to --to
(default the end):
the fluid particles' growth per 10 ms, the mean flows through the annulus and the aortic outlet (a closed valve
that holds: both near 0, and equal), the mean of the aorta probe's pressure less the Windkessel's (the outlet's
push on the fluid: near 0 when the fluid's density answers the volume it is given), and the largest number of
particles inside a wall; the largest density error (diagnostics.csv, every probe time) beside the largest
99.9th percentile and the most particles over 3 % in a frame (a few particles by the sheets carry the largest
error with mask_density: docs/validation.md, "Stop 54").

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


def frame_stats(run_dir, scene):
    """Time of each VTK frame -> (fluid particles inside a wall, 99.9th percentile of the fluid's density
    error [%], fluid particles with a density error over 3 %)."""
    dx = scene["resolution"]["spacing"]
    h = scene["resolution"].get("smoothing_ratio", 1.3) * dx
    fluid = vtk_run.bodies_of_type(scene, "fluid")
    walls = vtk_run.bodies_of_type(scene, "wall")
    rho0 = np.array([scene["materials"][b["material"]].get("density", 0.0) for b in scene["bodies"]])
    out = {}
    for t, path in vtk_run.frame_times(run_dir):
        d = {k: np.asarray(v) for k, v in study_report.read_vtp(path).items()}
        body = d["body"].astype(np.int64)
        fl = np.isin(body, fluid)
        frac = wall_leak.wall_fraction(d["Points"][fl], d["Points"][np.isin(body, walls)], dx, h)
        err = np.abs(d["density"][fl] / rho0[body[fl]] - 1.0)
        out[round(t, 6)] = (int((frac > 0.8).sum()), 100.0 * float(np.percentile(err, 99.9)), int((err > 0.03).sum()))
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
    frames = frame_stats(a.run_dir, scene)
    t = probes["time"]
    mm = lambda p: (p - BACKGROUND) / MMHG  # noqa: E731
    print("t [s]   fluid  volume_ratio  q_annulus  q_aorta [ml/s]  p_aorta  p_windkessel [mmHg]  in_wall"
          "  err_p99.9 [%]  n>3%")
    for k in range(len(t)):
        if abs(t[k] * 100 - round(t[k] * 100)) > 1e-6:
            continue
        d = int(np.argmin(np.abs(diag["time"] - t[k])))
        f = frames.get(round(t[k], 6))
        vtk = f"{f[0]:5d}  {f[1]:6.2f}  {f[2]:4d}" if f else ""
        print(f"{t[k]:.3f}  {int(diag['fluid'][d]):6d}  {diag['volume_ratio'][d]:.4f}  "
              f"{probes['q_annulus'][k] * 1e6:9.1f}  {probes['balance.aorta.flow'][k] * 1e6:9.1f}  "
              f"{mm(probes['p_aorta'][k]):8.1f}  {mm(probes['balance.aorta.pressure'][k]):8.1f}  {vtk}")
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
    print(f"  largest density error (diagnostics.csv): {100.0 * diag['max_density_error'][dw].max():.1f} %")
    seen = {k: v for k, v in frames.items() if a.t0 - 1e-9 <= k <= a.t1 + 1e-9}
    if seen:
        last = seen[max(seen)]
        print(f"  fluid particles inside a wall: at most {max(v[0] for v in seen.values())} (last frame {last[0]})")
        print(f"  density error, 99.9th percentile: at most {max(v[1] for v in seen.values()):.2f} %; particles over "
              f"3 %: at most {max(v[2] for v in seen.values())}")


if __name__ == "__main__":
    main()
