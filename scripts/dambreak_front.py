#!/usr/bin/env python3
"""Martin & Moyce (1952) dam break, n^2 = 2 (column a x 2a, a = 2.25 in): the surge front Z = x_front / a against
T = t sqrt(2 g / a), for the investigation of issue 20 item 1 (docs/validation.md, "Why the front leads").

The scene is the one of tests/builders.hpp dam_break(): tank 8a x 3a, slab `depth` spacings deep between two
walls, c0 = 10 sqrt(2 g 2a), nu = 1e-6, default delta-SPH 0.1. Options change one thing at a time: the spacing
(a / div), the walls' slip condition, the delta-SPH coefficient, the smoothing ratio. Three front columns: max x
of any water particle (`stat: max`), the continuous-fluid edge with the default link 2h (`stat: extent`) and with
link 1.5 dx. Prints Z and its error against the tabulated front (Table 2/6) at each tabulated 1 <= T <= 3.

usage: scripts/dambreak_front.py BINARY OUTDIR [--div 10] [--slip no_slip|free_slip] [--delta 0.1]
                                 [--depth 4] [--smoothing 1.3] [--c0-factor 10] [--gate 0] [--threads 2]
                                 [--end-T 3.0] [--shift 0]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REF = os.path.join(HERE, "..", "tests", "data", "dambreak_martin_moyce_tables_n2_2_a225in_front.csv")


def reference():
    rows = []
    with open(REF) as f:
        for line in f:
            if line.startswith("#") or line.startswith("T_"):
                continue
            T, Z = line.strip().split(",")
            rows.append((float(T), float(Z)))
    return rows


def scene(a, div, slip, delta, depth_layers, end_t, smoothing, c0_factor, gate):
    dx = a / div
    depth = depth_layers * dx
    c0 = c0_factor * math.sqrt(2 * 9.81 * 2 * a)
    tank = {"name": "tank", "material": "wall",
            "shape": {"container": {"min": [0, 0, 0], "max": [8 * a, 3 * a, depth], "layers": 3, "open": ["+y"]}}}
    if slip != "no_slip":
        tank["slip"] = slip
    bodies = [{"name": "column", "material": "water",
               "shape": {"box": {"min": [0, 0, 0], "max": [a, 2 * a, depth]}}}, tank]
    materials = {"water": {"type": "fluid", "density": 1000, "viscosity": 1e-6, "sound_speed": c0,
                           "delta_sph": delta},
                 "wall": {"type": "wall"}}
    top = 3 * a + 0.05
    if gate > 0:
        # A gate two spacings thick against the column's face, lifted at `gate` m/s from t = 0: a rigid body
        # so dense (1e5 kg/m^3) that the water's push hardly changes its motion (gravity slows it by g t).
        materials["gate"] = {"type": "rigid", "density": 1e5}
        bodies.append({"name": "gate", "material": "gate", "velocity": [0, gate, 0],
                       "shape": {"box": {"min": [a, 0, 0], "max": [a + 2 * dx, 2.2 * a, depth]}}})
        top = 2.2 * a + gate * end_t + 0.1
    return {
        "name": "dambreak_front",
        "domain": {"min": [-0.05, -0.05, -0.05], "max": [8 * a + 0.05, top, depth + 0.05]},
        "resolution": {"spacing": dx, "smoothing_ratio": smoothing},
        "time": {"end": end_t, "output_interval": 0.001, "cfl": 0.25, "max_dt": 1e-3},
        "gravity": [0, -9.81, 0],
        "materials": materials,
        "bodies": bodies,
        "probes": [
            {"name": "max", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "max"},
            {"name": "extent", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "extent"},
            {"name": "extent15", "type": "extent", "bodies": ["column"], "axis": "x", "stat": "extent",
             "link": 1.5 * dx},
        ],
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("out")
    ap.add_argument("--div", type=int, default=10)
    ap.add_argument("--slip", default="no_slip")
    ap.add_argument("--delta", type=float, default=0.1)
    ap.add_argument("--depth", type=int, default=4)
    ap.add_argument("--smoothing", type=float, default=1.3)
    ap.add_argument("--c0-factor", type=float, default=10.0, help="c0 over sqrt(2 g H), H = 2a")
    ap.add_argument("--gate", type=float, default=0.0, help="lift a gate at this speed [m/s] (0: no gate)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--end-T", type=float, default=3.0)
    ap.add_argument("--shift", type=float, default=0.0, help="report Z(T - shift) as well (time origin)")
    args = ap.parse_args()
    a = 0.05715
    scale = math.sqrt(2 * 9.81 / a)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "scene.json")
    with open(path, "w") as f:
        json.dump(scene(a, args.div, args.slip, args.delta, args.depth, args.end_T / scale + 0.002,
                        args.smoothing, args.c0_factor, args.gate), f, indent=1)
    if not os.path.exists(os.path.join(args.out, "probes.csv")):
        subprocess.run([args.binary, "run", path, "--out", args.out, "--no-render", "--quiet", "--threads",
                        str(args.threads)], check=True)
    with open(os.path.join(args.out, "probes.csv")) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["time"]) for r in rows]

    def at(col, T):
        tt = T / scale
        for k in range(1, len(t)):
            if t[k] >= tt:
                w = (tt - t[k - 1]) / (t[k] - t[k - 1])
                return ((1 - w) * float(rows[k - 1][col]) + w * float(rows[k][col])) / a
        return float("nan")

    print(f"# div {args.div} slip {args.slip} delta {args.delta} depth {args.depth} smoothing {args.smoothing} "
          f"c0 {args.c0_factor} sqrt(2gH) gate {args.gate} m/s")
    print("T,Z_exp,Z_max,err_max,Z_extent,err_extent,Z_extent15,err_extent15" +
          (",Z_max_shifted,err_shifted" if args.shift else ""))
    for T, Z in reference():
        if T < 1.0 or T > args.end_T:
            continue
        vals = [at(c, T) for c in ("max", "extent", "extent15")]
        line = f"{T},{Z}," + ",".join(f"{v:.3f},{100 * (v / Z - 1):+.1f}" for v in vals)
        if args.shift:
            v = at("max", T - args.shift)
            line += f",{v:.3f},{100 * (v / Z - 1):+.1f}"
        print(line)
    # The time origin: how much later the experiment reaches each tabulated Z than the simulated edge
    # (`extent`), and the one shift of the experiment's clock that fits best (largest error over 1 <= T <= 3).
    sel = [(T, Z) for T, Z in reference() if 1.0 <= T <= args.end_T]
    zs = [float(r["extent"]) / a for r in rows]
    lags = []
    for T, Z in sel:
        for k in range(1, len(t)):
            if zs[k] >= Z:
                tz = t[k - 1] + (Z - zs[k - 1]) / (zs[k] - zs[k - 1]) * (t[k] - t[k - 1])
                lags.append(T - tz * scale)
                break
    print("# lag T_exp - T_sim at equal Z (extent): " + " ".join(f"{x:.2f}" for x in lags))
    shifts = [0.01 * k for k in range(61)]
    worst = [max(abs(at("extent", T - d) / Z - 1) for T, Z in sel) for d in shifts]
    k = min(range(len(shifts)), key=lambda i: worst[i])
    print(f"# best shift dT = {shifts[k]:.2f} (t = {1000 * shifts[k] / scale:.1f} ms): largest |error| "
          f"{100 * worst[k]:.1f} %; early: Z(0.41) = {at('extent', 0.41):.3f} (exp 1.11), "
          f"Z(0.84) = {at('extent', 0.84):.3f} (exp 1.22)")


if __name__ == "__main__":
    sys.exit(main())
