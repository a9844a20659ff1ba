#!/usr/bin/env python3
"""Flow over Poiseuille's flow for runs of scenes/poiseuille_tube.json (open, pressure-driven) and
scenes/poiseuille_pipe.json (periodic, driven by a body force), from each run's probes.csv and run.json.

    scripts/poiseuille.py RUN_DIR...

The tube: mean flow q_mid over the window over pi R^4 G / (8 mu), G the gradient measured between the
probes p1 and p2 (and, beside it, the gradient the two boundaries impose). The pipe: the flow q over
pi R^4 g / (8 nu). R is the scene's fluid cylinder radius. Standard library only."""
import csv
import json
import math
import os
import sys


def load(run):
    with open(os.path.join(run, "run.json")) as f:
        scene = json.load(f)["scene"]
    with open(os.path.join(run, "probes.csv")) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    if not rows:
        sys.exit(f"{run}/probes.csv: no rows")
    return scene, rows


def mean(rows, col, t0, t1):
    v = [r[col] for r in rows if t0 - 1e-9 <= r["time"] <= t1 + 1e-9]
    return sum(v) / len(v) if v else float("nan")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for run in sys.argv[1:]:
        scene, rows = load(run)
        blood = scene["materials"]["blood"]
        nu = blood["viscosity"]  # kinematic (docs/scenes.md)
        mu = blood["density"] * nu
        body = next(b for b in scene["bodies"] if b["material"] == "blood")
        R = body["shape"]["cylinder"]["radius"]
        dx = scene["resolution"]["spacing"]
        t_last = rows[-1]["time"]
        out = [f"{run}: dx {dx * 1e3:.3g} mm, R = {R / dx:.1f} dx"]
        if "q_mid" in rows[0]:  # the open tube
            bounds = {b["name"]: b for b in scene["open_boundaries"]}
            L = bounds["outlet"]["point"][1] - bounds["inlet"]["point"][1]
            dp = bounds["inlet"]["pressure"] - bounds["outlet"]["pressure"]
            q_imposed = math.pi * R**4 * (dp / L) / (8 * mu)
            for t0, t1 in [(0.04, 0.16), (0.04, 0.4), (0.2, 0.4)]:
                if t_last < t1 - 1e-9:
                    continue
                G = (mean(rows, "p1", t0, t1) - mean(rows, "p2", t0, t1)) / (0.5 * L)
                q = mean(rows, "q_mid", t0, t1)
                out.append(f"{t0:g}-{t1:g} s: measured gradient {G:.0f} Pa/m (imposed {dp / L:.0f}), "
                           f"q / Poiseuille {q / (math.pi * R**4 * G / (8 * mu)):.3f} "
                           f"(of the imposed gradient {q / q_imposed:.3f})")
        else:  # the periodic pipe
            g = max(abs(c) for c in scene["gravity"])
            qp = math.pi * R**4 * g / (8 * nu)
            t0 = 0.08
            q = [r["q"] / qp for r in rows if r["time"] >= t0 - 1e-9]
            if q:
                out.append(f"from {t0:g} s: q / Poiseuille mean {sum(q) / len(q):.4f}, "
                           f"range {min(q):.4f} .. {max(q):.4f}")
        print("\n  ".join(out))


if __name__ == "__main__":
    main()
