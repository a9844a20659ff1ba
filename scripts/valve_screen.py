#!/usr/bin/env python3
"""Screen shell-leaflet variants without fluid: how far each opens and how well it coapts.

Each variant is scenes/shell_valve_closed.json (the physio scene's three shell leaflets, no wall, no fluid,
damped) with some `aortic_root` keys changed, run twice with `aortasph run`:
  closed: 80 mmHg on the aortic side, ramped over 6 ms (the shipped scene), coaptation probe at its end (12 ms);
  opened: 1000 Pa on the ventricular side from t = 0, an orifice_area probe, read at 10, 16 and 20 ms.
Under a minute per variant on one thread. docs/validation.md, "Stop 63", has the table this printed.

A variant is NAME or NAME:KEY=VALUE,KEY=VALUE,... where KEY is an aortic_root key (lunula_height,
lunula_radius, mirror_tilt, ...), `lunula_thickness` [m]: the lunula gets its own shell material, the
leaflet's with that thickness, `hourglass`: every sheet's hourglass control (the shell key, default
0.05), or `dynamic_viscosity`: every sheet's Kelvin-Voigt viscosity [Pa s] (the shell key, default 0).
Without variants the stop-63 set is run.

Usage: scripts/valve_screen.py [--bin build/aortasph] [--out out/valve_screen] [-j 2] [VARIANT ...]
"""
import argparse
import concurrent.futures
import copy
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

DEFAULT = [
    "none",
    "none_tilt9:mirror_tilt=9",
    "full:lunula_height=0.004",
    "full_tilt9:lunula_height=0.004,mirror_tilt=9",
    "full_tilt11:lunula_height=0.004,mirror_tilt=11",
    "thick6:lunula_height=0.004,lunula_radius=0.006,lunula_thickness=0.001",
    "thick9:lunula_height=0.004,lunula_radius=0.009,lunula_thickness=0.001",
    "thick10:lunula_height=0.004,lunula_radius=0.010,lunula_thickness=0.001",
    "thick11:lunula_height=0.004,lunula_radius=0.011,lunula_thickness=0.001",
    "thick10_h5:lunula_height=0.005,lunula_radius=0.010,lunula_thickness=0.001",
    "thick10_h6:lunula_height=0.006,lunula_radius=0.010,lunula_thickness=0.001",
    "thin10:lunula_height=0.004,lunula_radius=0.010",
    "mid10:lunula_height=0.004,lunula_radius=0.010,lunula_thickness=0.0007",
]


def bad(message):
    print(f"valve_screen.py: {message}", file=sys.stderr)
    sys.exit(2)


def parse_variant(text):
    name, _, spec = text.partition(":")
    keys = {}
    for item in filter(None, spec.split(",")):
        key, eq, value = item.partition("=")
        if not eq:
            bad(f"variant '{text}': '{item}' is not KEY=VALUE")
        try:
            keys[key] = float(value)
        except ValueError:
            bad(f"variant '{text}': '{value}' is not a number")
    return name, keys


def scene_of(base, keys, mode):
    s = copy.deepcopy(base)
    keys = dict(keys)
    thickness = keys.pop("lunula_thickness", None)
    hourglass = keys.pop("hourglass", None)
    viscosity = keys.pop("dynamic_viscosity", None)
    s["aortic_root"].update(keys)
    if thickness is not None:
        lunula = dict(s["materials"]["leaf"], thickness=thickness)
        s["materials"]["lunula"] = lunula
        s["aortic_root"]["lunula_material"] = "lunula"
    if hourglass is not None:
        for m in s["materials"].values():
            m["hourglass"] = hourglass
    if viscosity is not None:
        for m in s["materials"].values():
            if m.get("type") == "shell":
                m["dynamic_viscosity"] = viscosity
    for b in s["bodies"]:
        b["pressure_load"] = [[0, 0], [0.006, -10700]] if mode == "closed" else 1000
    if mode == "open":
        s["time"]["end"] = 0.02
        s["probes"].append({"name": "orifice", "type": "orifice_area",
                            "bodies": ["leaflet0", "leaflet1", "leaflet2"],
                            "point": [0, 0, 0], "normal": [0, 1, 0]})
    return s


def run(binary, out, base, name, keys, mode):
    d = os.path.join(out, f"{name}_{mode}")
    os.makedirs(d, exist_ok=True)
    path = d + ".json"
    with open(path, "w") as f:
        json.dump(scene_of(base, keys, mode), f)
    r = subprocess.run([binary, "run", path, "--out", d, "--threads", "1", "--no-render", "--quiet"],
                       capture_output=True, text=True)
    if r.returncode:
        return f"exit {r.returncode}: {r.stderr.strip()[-300:]}"
    with open(os.path.join(d, "probes.csv")) as f:
        rows = list(csv.DictReader(f))
    if mode == "closed":
        last = rows[-1]
        lines = [float(last[f"coapt.height_{a}_{b}"]) * 1e3 for a, b in ((0, 1), (0, 2), (1, 2))]
        return (f"coaptation per line {min(lines):.2f}-{max(lines):.2f} mm, central "
                f"{float(last['coapt.central_height']) * 1e3:.2f} mm, effective height "
                f"{float(last['coapt.effective_height']) * 1e3:.2f} mm")
    areas = []
    for t in (0.01, 0.016, 0.02):
        row = min(rows, key=lambda r: abs(float(r["time"]) - t))
        areas.append(float(row["orifice"]) * 1e4)
    return "opened " + " / ".join(f"{a:.2f}" for a in areas) + " cm² at 10 / 16 / 20 ms"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "aortasph"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "valve_screen"))
    ap.add_argument("-j", type=int, default=2)
    ap.add_argument("variants", nargs="*")
    a = ap.parse_args()
    with open(os.path.join(ROOT, "scenes", "shell_valve_closed.json")) as f:
        base = json.load(f)
    variants = [parse_variant(v) for v in (a.variants or DEFAULT)]
    jobs = [(name, keys, mode) for name, keys in variants for mode in ("open", "closed")]
    with concurrent.futures.ThreadPoolExecutor(a.j) as ex:
        results = list(ex.map(lambda j: run(a.bin, a.out, base, *j), jobs))
    for (name, keys, mode), result in zip(jobs, results):
        print(f"{name:12s} {mode:6s} {result}")
    if any(r.startswith("exit ") for r in results):
        sys.exit(1)  # a run failed (its message is in the table)


if __name__ == "__main__":
    main()
