#!/usr/bin/env python3
"""A lumped (0-D) model of a physiological scene, to set its SPH numbers beside: what the scene's own boundary
conditions would eject through an ideal valve.

    scripts/physio_lumped.py SCENE.json [--eoa CM2] [--length M] [--area M2] [--cycles N]

Reads the scene's pressure inlet (a waveform file, its units, offset and period) and its RCR outlet
(`windkessel`), both as the simulator does (absolute pressures in the fluid's terms; the fluid's background
pressure is subtracted for the printout). Between them: a valve that is open while the pressure difference
or the flow is forward and shut otherwise, with a Bernoulli loss through an effective orifice area (--eoa,
default 2.5 cm^2), and the inertance of the blood between the two discs, rho * length / area (--length, default
the distance between the two discs; --area, default the outlet disc's). Explicit Euler at 10 us over N cycles
(default 4), the RCR as in docs/model.md (C dPc/dt = Q - (Pc - Pd)/Rd, P_out = Pc + Rp Q).

Prints per cycle: stroke volume [ml], peak flow [ml/s], aortic (outlet) pressure max/min [mmHg], ejection time
[s], the valve's opening time in the cycle [s] and the time the shut valve holds the scene's cycle.hold_level
(default 70 mmHg) or more [s] (issue 17's "held" target: 0.4 s). Not a validation of the SPH model (a lumped valve has no leaflets); a check that a scene's boundary
conditions ask for physiological numbers at all (stop 42: the shipped physio scene's ask for 80 ml and 404 ml/s
in its first cycle).
"""
import argparse
import json
import math
import os
import sys

MMHG = 133.322


def fail(msg):
    print("physio_lumped.py: " + msg, file=sys.stderr)
    sys.exit(2)


def load_waveform(spec, scene_dir):
    if not isinstance(spec, dict) or "file" not in spec:
        fail("the inflow's pressure must be a waveform file object ({\"file\": ..., \"period\": ...})")
    path = os.path.join(scene_dir, spec["file"])
    scale = MMHG if spec.get("units", "Pa") == "mmHg" else 1.0
    offset = float(spec.get("offset", 0.0))
    times, values = [], []
    try:
        with open(path) as f:
            for n, line in enumerate(f, 1):
                line = line.strip()
                if not line or line.startswith("#"):
                    continue
                parts = line.split(",")
                try:
                    t, p = float(parts[0]), float(parts[1])
                except (ValueError, IndexError):
                    if not times:
                        continue  # a header line
                    fail("%s:%d: not 'time, pressure'" % (path, n))
                times.append(t)
                values.append(p * scale + offset)
    except OSError as e:
        fail("%s: %s" % (path, e.strerror))
    if len(times) < 2:
        fail("%s: fewer than two samples" % path)
    return times, values, float(spec.get("period", times[-1]))


def interp(times, values, t):
    if t <= times[0]:
        return values[0]
    if t >= times[-1]:
        return values[-1]
    lo, hi = 0, len(times) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    a = (t - times[lo]) / (times[hi] - times[lo])
    return values[lo] + a * (values[hi] - values[lo])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--eoa", type=float, default=2.5, help="effective orifice area of the open valve [cm^2]")
    ap.add_argument("--length", type=float, help="length of the blood column between the discs [m]")
    ap.add_argument("--area", type=float, help="its cross-section [m^2]")
    ap.add_argument("--cycles", type=int, default=4)
    a = ap.parse_args()
    try:
        with open(a.scene) as f:
            scene = json.load(f)
    except (OSError, ValueError) as e:
        fail("%s: %s" % (a.scene, e))
    obs = scene.get("open_boundaries", [])
    inlet = next((o for o in obs if o.get("type") == "inflow" and "pressure" in o), None)
    outlet = next((o for o in obs if o.get("type") == "outflow" and "windkessel" in o), None)
    if inlet is None or outlet is None:
        fail("%s: needs a pressure inflow and a windkessel outflow" % a.scene)
    blood = scene["materials"][scene["bodies"][[b["name"] for b in scene["bodies"]].index(inlet["body"])]["material"]]
    rho = float(blood["density"])
    background = float(blood.get("background_pressure", 0.0))
    times, values, period = load_waveform(inlet["pressure"], os.path.dirname(os.path.abspath(a.scene)))
    wk = outlet["windkessel"]
    rp, c, rd = float(wk["proximal_resistance"]), float(wk["capacitance"]), float(wk["distal_resistance"])
    pd, pc = float(wk["distal_pressure"]), float(wk["initial_pressure"])
    length = a.length if a.length else math.dist(inlet["point"], outlet["point"])
    area = a.area if a.area else math.pi * float(outlet["radius"]) ** 2
    inertance = rho * length / area
    eoa = a.eoa * 1e-4
    dt = 1e-5
    steps = int(round(period / dt))
    q = 0.0
    print("# %s: inertance %.3g Pa s^2/m^3 (length %.1f mm, area %.2f cm^2), EOA %.2f cm^2, RCR %.3g / %.3g / %.3g"
          % (a.scene, inertance, length * 1e3, area * 1e4, a.eoa, rp, c, rd))
    hold = float(scene.get("cycle", {}).get("hold_level", 70.0 * MMHG))
    print("cycle, stroke_volume_ml, peak_flow_ml_s, aortic_max_mmHg, aortic_min_mmHg, ejection_s, opening_s, held_s")
    for cycle in range(a.cycles):
        sv = qmax = ejection = held = 0.0
        opening = None
        pmax, pmin = -1e300, 1e300
        for n in range(steps):
            t = n * dt
            p_lv = interp(times, values, t % period)
            p_out = pc + rp * q
            dp = p_lv - p_out
            if q <= 0.0 and dp <= 0.0:
                q = 0.0  # shut
            else:
                q = max(0.0, q + dt * (dp - 0.5 * rho * (q / eoa) ** 2) / inertance)
            pc += dt * (q - (pc - pd) / rd) / c
            sv += q * dt
            qmax = max(qmax, q)
            if q > 0.0:
                ejection += dt
                opening = t if opening is None else opening
            elif p_out - p_lv >= hold:
                held += dt
            pmax, pmin = max(pmax, p_out), min(pmin, p_out)
        print("%d, %.1f, %.0f, %.1f, %.1f, %.3f, %.3f, %.3f" % (
            cycle + 1, sv * 1e6, qmax * 1e6, (pmax - background) / MMHG, (pmin - background) / MMHG, ejection,
            opening if opening is not None else float("nan"), held))


if __name__ == "__main__":
    main()
