#!/usr/bin/env python3
"""Wiggers diagram of a finished aortasph run: LV and aortic pressure, flow through the valve and orifice area
against time, stacked panels sharing the time axis, the last cycle's metrics beside them.

Usage: plot_wiggers.py OUT_DIR [PNG [PRESSURE_ZERO_PA]]   (default PNG: OUT_DIR/figures/wiggers.png)

The pressures are drawn less PRESSURE_ZERO_PA (the scene's cycle.pressure_zero; default: what run.json
records as cycles.pressure_zero_Pa, else 0), as the metrics in cycles.csv read them.

Reads OUT_DIR/run.json (the scene's "cycle" block names the probe columns), OUT_DIR/probes.csv and
OUT_DIR/cycles.csv. `aortasph plot OUT_DIR` runs this script (embedded in the binary) after checking the
files. Needs matplotlib (Debian: python3-matplotlib). Exit 2 on a missing file or column.
"""
import csv
import json
import math
import os
import sys

MMHG = 133.322387415  # Pa


def fail(message):
    sys.stderr.write("plot_wiggers: error: " + message + "\n")
    sys.exit(2)


def read_table(path):
    if not os.path.isfile(path):
        fail(path + ": missing")
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        fail(path + ": empty")
    header = rows[0]
    data = []
    for row in rows[1:]:
        if row:
            data.append([float(c) if c not in ("", "nan") else math.nan for c in row])
    return header, data


def column(header, data, name, path):
    if name not in header:
        fail(path + ": no column '" + name + "'")
    k = header.index(name)
    return [r[k] for r in data]


def main(argv):
    if len(argv) < 1 or len(argv) > 3:
        fail("usage: plot_wiggers.py OUT_DIR [PNG [PRESSURE_ZERO_PA]]")
    out_dir = argv[0]
    png = argv[1] if len(argv) >= 2 else os.path.join(out_dir, "figures", "wiggers.png")
    run_json = os.path.join(out_dir, "run.json")
    if not os.path.isfile(run_json):
        fail(run_json + ": missing")
    with open(run_json) as f:
        run = json.load(f)
    cycle = run.get("scene", {}).get("cycle")
    if not cycle:
        fail(run_json + ": the scene has no cycle block")
    # The fluid pressure that reads 0 mmHg (cycle.pressure_zero, resolved by aortasph): the argument, else
    # what run.json recorded, else 0 (runs before stop 57).
    if len(argv) == 3:
        try:
            zero = float(argv[2])
        except ValueError:
            fail("PRESSURE_ZERO_PA: expected a number, got '" + argv[2] + "'")
    else:
        zero = float(run.get("cycles", {}).get("pressure_zero_Pa", 0.0))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    probes = os.path.join(out_dir, "probes.csv")
    header, data = read_table(probes)
    t = column(header, data, "time", probes)
    lv = [(p - zero) / MMHG for p in column(header, data, cycle["lv_pressure"], probes)]
    ao = [(p - zero) / MMHG for p in column(header, data, cycle["aortic_pressure"], probes)]
    q = [v * 1e6 for v in column(header, data, cycle["valve_flow"], probes)]
    area = None
    if cycle.get("orifice_area"):
        area = [a * 1e4 for a in column(header, data, cycle["orifice_area"], probes)]

    cycles_csv = os.path.join(out_dir, "cycles.csv")
    cheader, cdata = read_table(cycles_csv)
    last = dict(zip(cheader, cdata[-1])) if cdata else {}

    panels = 3 if area is not None else 2
    fig = plt.figure(figsize=(11, 2.6 * panels + 0.8))
    grid = fig.add_gridspec(panels, 2, width_ratios=[3.2, 1.3], wspace=0.05, hspace=0.08)
    axes = [fig.add_subplot(grid[0, 0])]
    for k in range(1, panels):
        axes.append(fig.add_subplot(grid[k, 0], sharex=axes[0]))

    axes[0].plot(t, lv, color="tab:red", lw=1.2, label="LV (upstream)")
    axes[0].plot(t, ao, color="tab:blue", lw=1.2, label="aortic (downstream)")
    axes[0].set_ylabel("pressure [mmHg]" if zero == 0.0 else "pressure [mmHg] (0 at %g Pa)" % zero)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].plot(t, q, color="black", lw=1.2)
    axes[1].axhline(0.0, color="grey", lw=0.6)
    axes[1].set_ylabel("valve flow [ml/s]")
    if area is not None:
        axes[2].plot(t, area, color="tab:green", lw=1.2)
        axes[2].set_ylabel("orifice area [cm$^2$]")
    axes[-1].set_xlabel("time [s]")
    for ax in axes[:-1]:
        plt.setp(ax.get_xticklabels(), visible=False)
    for ax in axes:
        ax.grid(True, lw=0.3, alpha=0.6)
        if last:
            ax.axvspan(last["t_start_s"], last["t_end_s"], color="0.92", zorder=0)

    # The last cycle's metrics beside the panels.
    text_ax = fig.add_subplot(grid[:, 1])
    text_ax.axis("off")
    rows = [
        ("stroke volume", "stroke_volume_ml", "ml"),
        ("cardiac output", "cardiac_output_l_min", "l/min"),
        ("peak forward flow", "peak_forward_flow_ml_s", "ml/s"),
        ("peak jet velocity", "peak_jet_velocity_m_s", "m/s"),
        ("peak gradient", "peak_gradient_mmHg", "mmHg"),
        ("mean gradient", "mean_gradient_mmHg", "mmHg"),
        ("peak GOA", "peak_goa_cm2", "cm2"),
        ("EOA (Gorlin)", "eoa_gorlin_cm2", "cm2"),
        ("EOA (continuity)", "eoa_continuity_cm2", "cm2"),
        ("opening time", "opening_time_ms", "ms"),
        ("closing time", "closing_time_ms", "ms"),
        ("closing volume", "closing_volume_ml", "ml"),
        ("leakage volume", "leakage_volume_ml", "ml"),
        ("regurgitant fraction", "regurgitant_fraction_pct", "%"),
        ("diastolic dp (mean)", "diastolic_dp_mean_mmHg", "mmHg"),
        ("aortic sys / dia", None, "mmHg"),
        ("stress diastole peak", "stress_diastole_peak_kPa", "kPa"),
        ("effective height", "effective_height_mm", "mm"),
        ("max density error", "max_density_error_pct", "%"),
        ("LV noise (ejection)", "lv_noise_Pa", "Pa"),
    ]

    def fmt(v):
        return "--" if v is None or (isinstance(v, float) and math.isnan(v)) else "%.3g" % v

    lines = []
    if last:
        lines.append("cycle %d  [%.3g, %.3g] s" % (int(last["cycle"]), last["t_start_s"], last["t_end_s"]))
        periodic = last.get("periodic")
        lines.append("periodic state: " + ("--" if periodic is None or math.isnan(periodic)
                                             else ("yes" if periodic > 0.5 else "no")))
        lines.append("")
        for label, key, unit in rows:
            if key is None:
                value = fmt(last.get("aortic_systolic_mmHg")) + " / " + fmt(last.get("aortic_diastolic_mmHg"))
            else:
                value = fmt(last.get(key))
            lines.append("%-21s %9s %s" % (label, value, unit))
    else:
        lines.append("no complete cycle")
    text_ax.text(0.02, 0.98, "\n".join(lines), va="top", ha="left", family="monospace", fontsize=8.5,
                 transform=text_ax.transAxes)
    fig.suptitle("Wiggers diagram: " + os.path.basename(os.path.normpath(out_dir)), fontsize=11)
    os.makedirs(os.path.dirname(png) or ".", exist_ok=True)
    fig.savefig(png, dpi=110, bbox_inches="tight")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
