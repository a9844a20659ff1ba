#!/usr/bin/env python3
"""Particle-scale noise of the blood in an aortic run (issue 20 item 6).

Reads the VTK frames (`aortasph run ... --vtk-every N`, ASCII .vtp) of one or more runs and reports, for the
blood particles inside a cylinder about the root's axis (the jet and the sinuses), at each frame:

  vel_noise   RMS over particles of |v_i - <v>_i| / RMS |<v>_i|, where <v>_i is the value at x_i of the linear
              least-squares fit of the velocity over the blood particles within the kernel support 2h (cubic
              spline weights, i included). A linear field (uniform flow, shear, strain) gives exactly 0; the
              curvature of the real field over 2h adds a little; particle-to-particle jitter raises it.
  p_noise     RMS of p_i - <p>_i [Pa], the same fit of the pressure: the particle-scale pressure noise.
  close       share of blood particles whose nearest blood neighbour is closer than dx/2 (clumping).
  nn_cv       coefficient of variation of the nearest-neighbour distance (0 on a lattice; disorder raises it).

Usage: jet_noise.py --dx 0.001 [--h-ratio 1.3] [--body 2] [--radius 0.011] [--ymin 0.002] [--ymax 0.024]
                    [--json OUT.json] LABEL=RUN_DIR [LABEL=RUN_DIR ...]
RUN_DIR is the run's output folder (it holds vtk/particles.pvd). The body index is the blood body's position in
the scene's `bodies` list (2 in scenes/aortic_root.json).
"""
import argparse
import csv
import json
import math
import os
import sys

import numpy as np
from scipy.spatial import cKDTree

import study_report  # noqa: E402 (same folder: its .vtp reader)
import vtk_run  # noqa: E402


def read_vtp(path):
    """study_report.py's reader of the ascii .vtp files, as numpy arrays ('Points' is the positions)."""
    return {name: np.asarray(values, dtype=float) for name, values in study_report.read_vtp(path).items()}


def cubic_w(q):
    """Cubic spline shape (unnormalised: the Shepard ratio cancels the constant)."""
    w = np.zeros_like(q)
    a = q < 1.0
    w[a] = 1.0 - 1.5 * q[a] ** 2 + 0.75 * q[a] ** 3
    b = (q >= 1.0) & (q < 2.0)
    w[b] = 0.25 * (2.0 - q[b]) ** 3
    return w


def noise(arr, args, want_fields=False):
    x = arr['Points']
    body = arr['body'].astype(int)
    blood = body == args.body
    xb, vb, pb = x[blood], arr['velocity'][blood], arr['pressure'][blood]
    h = args.h_ratio * args.dx
    tree = cKDTree(xb)
    r_axis = np.hypot(xb[:, 0], xb[:, 2])
    sel = np.where((r_axis < args.radius) & (xb[:, 1] > args.ymin) & (xb[:, 1] < args.ymax))[0]
    if len(sel) == 0:
        return None
    pairs = tree.query_ball_point(xb[sel], 2.0 * h)
    dv2, vbar2, dp2 = [], [], []
    for k, i in enumerate(sel):
        js = np.asarray(pairs[k])
        dxj = xb[js] - xb[i]
        w = cubic_w(np.linalg.norm(dxj, axis=1) / h)
        # Weighted least-squares linear fit f(x) = a + b.(x - x_i) over the neighbours (i included): the fit's
        # value a at x_i is the smooth field there; a uniform shear or strain leaves no residual.
        basis = np.hstack([np.ones((len(js), 1)), dxj / h])
        sw = np.sqrt(w)[:, None]
        coef_v, *_ = np.linalg.lstsq(basis * sw, vb[js] * sw, rcond=None)
        coef_p, *_ = np.linalg.lstsq(basis * sw, pb[js][:, None] * sw, rcond=None)
        vbar, pbar = coef_v[0], coef_p[0, 0]
        dv2.append(float(((vb[i] - vbar) ** 2).sum()))
        vbar2.append(float((vbar ** 2).sum()))
        dp2.append(float((pb[i] - pbar) ** 2))
    d, _ = tree.query(xb[sel], k=2)
    nn = d[:, 1]
    if want_fields:
        return xb[sel], np.linalg.norm(vb[sel], axis=1), np.sqrt(np.array(dv2))
    return {
        'particles': int(len(sel)),
        'vel_noise': math.sqrt(np.mean(dv2)) / max(math.sqrt(np.mean(vbar2)), 1e-12),
        'rms_speed': math.sqrt(np.mean(vbar2)),
        'p_noise': math.sqrt(np.mean(dp2)),
        'close': float(np.mean(nn < 0.5 * args.dx)),
        'nn_cv': float(nn.std() / nn.mean()),
    }


def plot_sections(args):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    runs = [spec.split('=', 1) for spec in args.runs]
    wide = argparse.Namespace(**vars(args))  # the whole lumen in the pictures, not only the measured region
    wide.radius, wide.ymin, wide.ymax = 1.0, -1.0, 1.0
    fig, axes = plt.subplots(len(runs), 3, figsize=(12, 5.0 * len(runs)), squeeze=False)
    for row, (label, run_dir) in enumerate(runs):
        fr = vtk_run.frame_times(run_dir)[-2:]
        for col in range(3):
            t, path = fr[min(col, len(fr) - 1)]
            x, speed, res = noise(read_vtp(path), wide, want_fields=True)
            cut = np.abs(x[:, 2]) < 0.5 * args.dx
            ax = axes[row, col]
            if col < 2:
                sc = ax.scatter(1e3 * x[cut, 0], 1e3 * x[cut, 1], c=speed[cut], s=12, cmap='viridis', vmin=0, vmax=2.0)
                what = f'speed, t = {1e3 * t:.0f} ms'
            else:
                sc = ax.scatter(1e3 * x[cut, 0], 1e3 * x[cut, 1], c=res[cut], s=12, cmap='magma_r', vmin=0, vmax=0.5)
                what = f'|v - <v>|, t = {1e3 * t:.0f} ms'
            fig.colorbar(sc, ax=ax, shrink=0.6, label='m/s')
            ax.set_aspect('equal')
            ax.set_title(f'{label}: {what}', fontsize=9)
            ax.set_xlabel('x [mm]')
            ax.set_ylabel('y [mm]')
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)


def valve_numbers(run_dir):
    """The main job's valve numbers from probes.csv (scenes/aortic_root.json's probe names)."""
    path = os.path.join(run_dir, 'probes.csv')
    if not os.path.exists(path):
        return None
    rows = list(csv.DictReader(open(path)))
    if not rows or 'orifice' not in rows[0]:
        return None
    col = lambda k: np.array([float(r[k]) for r in rows])
    t = col('time')
    late = t >= 0.03 - 1e-9  # the plateau of the inflow (ramped over 0-30 ms)
    out = {
        'peak_orifice_cm2': float(col('orifice').max() * 1e4),
        'mean_orifice_30_60ms_cm2': float(col('orifice')[late].mean() * 1e4),
        'peak_q_aorta_ml_s': float(col('q_aorta').max() * 1e6),
        'peak_stress_kPa': float(col('leaflet_stress.max').max() / 1e3),
        'mean_dp_30_60ms_Pa': float((col('p_lvot') - col('p_aorta'))[late].mean()),
    }
    if 'balance.volume_inside' in rows[0]:
        v = col('balance.volume_inside')
        out['volume_inside_change_pct'] = float(100 * (v[-1] / v[0] - 1))
        vin, vout = col('balance.volume_in')[-1], col('balance.volume_out')[-1]
        out['in_minus_out_pct_of_in'] = float(100 * (vin - vout) / vin) if vin > 0 else 0.0
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--dx', type=float, required=True)
    ap.add_argument('--h-ratio', type=float, default=1.3)
    ap.add_argument('--body', type=int, default=2)
    ap.add_argument('--radius', type=float, default=0.011)
    ap.add_argument('--ymin', type=float, default=0.002)
    ap.add_argument('--ymax', type=float, default=0.024)
    ap.add_argument('--json')
    ap.add_argument('--png', help='a section |z| < dx/2 of each run (rows): speed at the last two frames and '
                                  'the velocity residual |v - <v>| at the last one (matplotlib)')
    ap.add_argument('runs', nargs='+', help='LABEL=RUN_DIR')
    args = ap.parse_args()
    result = {}
    print(f'{"run":<14} {"t [s]":>6} {"n":>6} {"vel_noise":>9} {"rms|v| m/s":>10} {"p_noise Pa":>10} '
          f'{"close":>7} {"nn_cv":>6}')
    for spec in args.runs:
        if '=' not in spec:
            sys.exit(f'{spec}: expected LABEL=RUN_DIR')
        label, run_dir = spec.split('=', 1)
        result[label] = []
        for t, path in vtk_run.frame_times(run_dir):
            r = noise(read_vtp(path), args)
            if r is None:
                continue
            r['t'] = t
            result[label].append(r)
            print(f'{label:<14} {t:6.3f} {r["particles"]:6d} {r["vel_noise"]:9.4f} {r["rms_speed"]:10.3f} '
                  f'{r["p_noise"]:10.1f} {100 * r["close"]:6.2f}% {r["nn_cv"]:6.3f}')
    print()
    for spec in args.runs:
        label, run_dir = spec.split('=', 1)
        v = valve_numbers(run_dir)
        if v:
            result[label + ':valve'] = v
            print(f'{label:<14} ' + '  '.join(f'{k} {val:.3g}' for k, val in v.items()))
    if args.png:
        plot_sections(args)
    if args.json:
        with open(args.json, 'w') as f:
            json.dump(result, f, indent=1)


if __name__ == '__main__':
    main()
