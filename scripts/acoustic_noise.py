#!/usr/bin/env python3
"""Acoustic noise of a pressure probe (issue 17 item 3): the RMS of a pressure column about its centred
running mean over a time window, and a plot of both.

Usage: acoustic_noise.py PROBES_CSV [--column p_lvot] [--from T0] [--to T1] [--window 0.01] [--png PNG]
                         [--label TEXT]

The running mean at a sample t is the mean of the samples within t +- window/2 (a centred boxcar; the
samples must be evenly spaced, e.g. probes written at time.output_interval <= 1 ms). Only samples whose whole
window lies inside the file count. Prints one line:
    noise <column> [T0, T1] window W: rms R Pa (peak-to-peak P Pa, mean M Pa, N samples, dt D s)
and writes the plot when --png is given. --column matches a probe column exactly or by its probe name
(`p_lvot` finds `p_lvot.pressure`). Exit 2 on a missing file, column or too few samples.
Needs numpy and matplotlib (Debian: python3-numpy, python3-matplotlib).
"""
import argparse
import sys

import numpy as np


def fail(message):
    sys.stderr.write("acoustic_noise: error: " + message + "\n")
    sys.exit(2)


def load(path, column):
    try:
        with open(path) as f:
            header = f.readline().strip().split(",")
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    names = [c for c in header if c == column or c.split(".")[0] == column]
    if not names:
        fail(f"{path}: no column '{column}' (have: {', '.join(header)})")
    data = np.genfromtxt(path, delimiter=",", skip_header=1)
    if data.ndim != 2 or data.shape[0] < 3:
        fail(f"{path}: fewer than 3 rows")
    return data[:, 0], data[:, header.index(names[0])], names[0]


def noise(t, p, t0, t1, window):
    """RMS of p about its centred running mean over [t0, t1]. Returns (rms, p2p, mean, sel, running, dt)."""
    dt = float(np.median(np.diff(t)))
    if dt <= 0:
        fail("times do not increase")
    half = int(round(0.5 * window / dt))
    if half < 1:
        fail(f"window {window} s is shorter than two samples (dt {dt} s)")
    kernel = np.ones(2 * half + 1) / (2 * half + 1)
    running = np.full_like(p, np.nan)
    running[half:len(p) - half] = np.convolve(p, kernel, mode="valid")
    sel = (t >= t0 - 1e-9) & (t <= t1 + 1e-9) & np.isfinite(running) & np.isfinite(p)
    if sel.sum() < 3:
        fail(f"fewer than 3 samples in [{t0}, {t1}] with a full {window} s window")
    dev = p[sel] - running[sel]
    return (float(np.sqrt(np.mean(dev * dev))), float(np.ptp(p[sel])), float(np.mean(p[sel])), sel, running,
            dt)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("probes")
    ap.add_argument("--column", default="p_lvot")
    ap.add_argument("--from", dest="t0", type=float, default=0.0)
    ap.add_argument("--to", dest="t1", type=float, default=float("inf"))
    ap.add_argument("--window", type=float, default=0.01)
    ap.add_argument("--png")
    ap.add_argument("--label", default="")
    a = ap.parse_args()
    t, p, name = load(a.probes, a.column)
    rms, p2p, mean, sel, running, dt = noise(t, p, a.t0, a.t1, a.window)
    t1 = min(a.t1, float(t[sel][-1]))
    print(f"noise {name} [{a.t0:g}, {t1:g}] s window {a.window:g} s: rms {rms:.1f} Pa "
          f"(peak-to-peak {p2p:.1f} Pa, mean {mean:.1f} Pa, {int(sel.sum())} samples, dt {dt:g} s)")
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
        ax[0].plot(t * 1e3, p, lw=0.8, label=name)
        ax[0].plot(t * 1e3, running, lw=1.5, label=f"{a.window * 1e3:g} ms running mean")
        ax[0].set_ylabel("pressure [Pa]")
        ax[0].legend(loc="best", fontsize=8)
        ax[0].set_title(f"{a.label} noise rms {rms:.0f} Pa over {a.t0 * 1e3:g}-{t1 * 1e3:g} ms".strip())
        ax[1].plot(t * 1e3, p - running, lw=0.8, color="k")
        ax[1].axvspan(a.t0 * 1e3, t1 * 1e3, color="0.9")
        ax[1].axhline(133.3, color="r", lw=0.6, ls="--")
        ax[1].axhline(-133.3, color="r", lw=0.6, ls="--", label="+-1 mmHg")
        ax[1].set_ylabel("p - running mean [Pa]")
        ax[1].set_xlabel("t [ms]")
        ax[1].legend(loc="best", fontsize=8)
        fig.tight_layout()
        fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
