#!/usr/bin/env python3
"""Lobovsky et al. (2014) dam break, H = 300 mm: the first impact on the far wall, simulated against measured.

Reads the probes.csv of runs of scenes/dam_break_lobovsky.json (columns P1..P4: the wall sensors, `pressure`
probes with a sensor face, docs/scenes.md) and the measured series in ../shared/validation (or --data), and
prints, per sensor and run, the first impact's peak pressure p/(rho g H) and its time t sqrt(g/H) against the
measured ones, with the relative errors (issue 20's target: both within 15 %). With --png it draws the
series over the impact (matplotlib).

Definitions (docs/validation.md, "Dam break against Lobovsky et al. 2014"):
- the first impact's window is t* from 2.0 to the arrival + 0.6, the arrival being the first t* at which the
  sensor reads more than 0.2 rho g H (sensors 1-3 are under the first jet; sensor 4 is reached by the run-up);
- the peak is the largest value in that window, its time the peak's time;
- the impulse mean is the mean of p/(rho g H) over the 0.3 (52 ms) of t* that follow the arrival: the
  pressure impulse of the impact divided by that time, a measure that does not hang on one sample;
- --smooth MS replaces each simulated series by its centred running mean over MS milliseconds first (the
  sensor's and the acquisition's band limit; 0: raw).

usage: lobovsky.py RUN_DIR[:LABEL] ... [--data DIR] [--png FILE] [--smooth MS] [--json FILE]
"""
import argparse
import csv
import json
import math
import os
import sys

G, H, RHO = 9.81, 0.3, 1000.0
TSCALE = math.sqrt(G / H)
PSCALE = RHO * G * H
SENSORS = ["P1", "P2", "P3", "P4"]
HEIGHTS_MM = [3, 15, 30, 80]


def read_series(path, tcol, pcols):
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    head, body = rows[0], rows[1:]
    ti = head.index(tcol)
    out = {c: [] for c in pcols}
    t = []
    for r in body:
        t.append(float(r[ti]))
        for c in pcols:
            out[c].append(float(r[head.index(c)]))
    return t, out


def running_mean(t, p, width):
    if width <= 0:
        return p
    out, lo, hi, s = [], 0, 0, 0.0
    n = len(t)
    for i in range(n):
        while hi < n and t[hi] <= t[i] + width / 2:
            s += p[hi]
            hi += 1
        while t[lo] < t[i] - width / 2:
            s -= p[lo]
            lo += 1
        out.append(s / (hi - lo))
    return out


def first_impact(ts, ps):
    """(arrival, peak, peak time, impulse mean) in nondimensional units, or None when the sensor stays dry."""
    arrival = next((t for t, p in zip(ts, ps) if t >= 2.0 and p > 0.2), None)
    if arrival is None:
        return None
    window = [(p, t) for t, p in zip(ts, ps) if 2.0 <= t <= arrival + 0.6]
    peak, when = max(window)
    # Trapezoidal integral over [arrival, arrival + 0.3] divided by 0.3.
    seg = [(t, p) for t, p in zip(ts, ps) if arrival <= t <= arrival + 0.3]
    integral = sum(0.5 * (p0 + p1) * (t1 - t0) for (t0, p0), (t1, p1) in zip(seg, seg[1:]))
    return arrival, peak, when, integral / 0.3


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="run folders (with probes.csv), optionally RUN:LABEL")
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "validation"))
    ap.add_argument("--png")
    ap.add_argument("--smooth", type=float, default=0.0, help="running mean over this many ms (0: raw)")
    ap.add_argument("--json", help="write the table as JSON here")
    a = ap.parse_args()

    exp = {}
    for k, s in enumerate(SENSORS):
        path = os.path.join(a.data, f"dambreak_lobovsky2014_H300mm_pressure_{s}.csv")
        if not os.path.exists(path):
            sys.exit(f"lobovsky.py: {path}: no such file (give --data)")
        t, p = read_series(path, "t_sqrt_g_over_H", ["p_over_rho_g_H"])
        exp[s] = (t, p["p_over_rho_g_H"], first_impact(t, p["p_over_rho_g_H"]))

    runs = []
    for spec in a.runs:
        folder, _, label = spec.partition(":")
        path = os.path.join(folder, "probes.csv")
        if not os.path.exists(path):
            sys.exit(f"lobovsky.py: {path}: no such file")
        t, cols = read_series(path, "time", SENSORS)
        ts = [x * TSCALE for x in t]
        width = a.smooth * 1e-3 * TSCALE
        series = {s: running_mean(ts, [v / PSCALE for v in cols[s]], width) for s in SENSORS}
        runs.append((label or os.path.basename(os.path.normpath(folder)), ts, series))

    table = []
    print(f"first impact (running mean {a.smooth:g} ms): peak p/(rho g H) and its time t sqrt(g/H); error = sim/exp - 1")
    print(f"{'sensor':8} {'run':22} {'peak':>7} {'exp':>7} {'err':>8} {'t_peak':>7} {'exp':>7} {'err':>8} {'arrival':>8} {'exp':>7}"
          f" {'impulse':>8} {'exp':>7} {'err':>8}")
    for k, s in enumerate(SENSORS):
        ea, ep, et, ei = exp[s][2]
        for label, ts, series in runs:
            r = first_impact(ts, series[s])
            row = {"sensor": s, "height_mm": HEIGHTS_MM[k], "run": label, "exp_peak": ep, "exp_time": et,
                   "exp_arrival": ea, "exp_impulse_mean": ei}
            if r is None:
                print(f"{s:8} {label:22} {'dry':>7}")
            else:
                arr, pk, tk, im = r
                row.update(peak=pk, time=tk, arrival=arr, impulse_mean=im, peak_err=pk / ep - 1,
                           time_err=tk / et - 1, impulse_err=im / ei - 1)
                print(f"{s:8} {label:22} {pk:7.3f} {ep:7.3f} {100 * (pk / ep - 1):+7.1f}% {tk:7.3f} {et:7.3f} "
                      f"{100 * (tk / et - 1):+7.1f}% {arr:8.3f} {ea:7.3f} {im:8.3f} {ei:7.3f} "
                      f"{100 * (im / ei - 1):+7.1f}%")
            table.append(row)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"smooth_ms": a.smooth, "rows": table}, f, indent=1)

    if a.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(2, 2, figsize=(12, 8), sharex=True)
        for ax, s, hmm in zip(axes.flat, SENSORS, HEIGHTS_MM):
            t, p, _ = exp[s]
            ax.plot(t, p, color="k", lw=1.5, label="Lobovsky et al. 2014 (event 5)")
            for label, ts, series in runs:
                ax.plot(ts, series[s], lw=0.9, label=label)
            ax.set_xlim(2.2, 4.0)
            ax.set_title(f"{s}: {hmm} mm above the floor")
            ax.set_ylabel(r"$p/(\rho g H)$")
            ax.grid(alpha=0.3)
        for ax in axes[1]:
            ax.set_xlabel(r"$t\,(g/H)^{1/2}$")
        axes[0, 0].legend(fontsize=8)
        fig.suptitle(f"Dam break H = 300 mm, wall pressure (simulated: running mean {a.smooth:g} ms)")
        fig.tight_layout()
        fig.savefig(a.png, dpi=110)
        print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
