#!/usr/bin/env python3
# The report of an aortasph study (docs/studies.md): DIR/metrics.csv (one row per variant: its parameters and
# the requested metrics of its last cycle, empty where missing) and DIR/report.html (readable offline: the
# table, one plot per swept parameter against each metric, each variant's Wiggers plot and figure sheets, and a
# header with the leaflet model, the boundary conditions and the resolution). Standard library + matplotlib.
# Usage: study_report.py DIR (the folder `aortasph study` wrote: study.json, variants.csv, variants/<id>/).
import csv
import html
import json
import math
import os
import sys


def read_csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


def number(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def leaflet_model(scene):
    """The solid model of the scene's leaflets, from its resolved JSON (run.json 'scene')."""
    materials = scene.get("materials", {})
    used = []
    for body in scene.get("bodies", []):
        m = materials.get(body.get("material"), {})
        kind = m.get("type")
        if kind in ("fluid", "wall", "rigid", None):
            continue
        used.append((body.get("name"), body.get("material"), m))
    if not used:
        return "no deformable leaflets in the scene"
    seen = {}
    for name, mat, m in used:
        seen.setdefault(mat, (m, []))[1].append(name)
    parts = []
    for mat, (m, names) in seen.items():
        kind = m.get("type")
        if kind == "elastic":
            what = "volumetric TL-SPH elastic solid (total Lagrangian SPH, particles through the thickness)"
        elif kind == "shell":
            what = "thin-shell leaflets"
        else:
            what = "material type '%s'" % kind
        extra = []
        for key, label in (("model", "model"), ("youngs_modulus", "E [Pa]"), ("poisson_ratio", "nu"),
                           ("thickness", "thickness [m]")):
            if key in m:
                extra.append("%s %s" % (label, m[key]))
        parts.append("%s: %s (%s; bodies %s)" % (mat, what, ", ".join(extra), ", ".join(names)))
    return "; ".join(parts)


def series_text(v):
    if isinstance(v, list):
        ys = [p[1] for p in v if isinstance(p, list) and len(p) == 2]
        if ys:
            return "table over time, %g to %g" % (min(ys), max(ys))
        return "table"
    return "constant %g" % v if isinstance(v, (int, float)) else str(v)


def boundary_conditions(scene):
    out = []
    for b in scene.get("open_boundaries", []):
        name = b.get("name", "?")
        if b.get("type") == "inflow":
            if "velocity" in b:
                out.append("%s: velocity inlet (mean velocity [m/s] %s, %s profile)" %
                           (name, series_text(b["velocity"]), b.get("profile", "uniform")))
            elif "pressure" in b:
                out.append("%s: pressure inlet (%s Pa)" % (name, series_text(b["pressure"])))
            else:
                out.append("%s: inlet (%s)" % (name, ", ".join(sorted(b))))
        else:
            if "windkessel" in b:
                out.append("%s: Windkessel outlet (%s)" % (name, json.dumps(b["windkessel"])))
            elif "pressure" in b:
                out.append("%s: pressure outlet (%s Pa)" % (name, series_text(b["pressure"])))
            else:
                out.append("%s: outlet (%s)" % (name, ", ".join(sorted(b))))
    return out or ["no open boundaries (closed domain)"]


# Clinical targets of a repaired valve (issue 19 item 5): effective height 9-10 mm (Schaefers et al. 2006;
# Bierbach et al. 2010), coaptation height >= 4 mm. (low, high) in the metric's unit; None: open.
TARGETS = {"effective_height_mm": (9.0, 10.0)}


def target_of(metric):
    if metric in TARGETS:
        return TARGETS[metric]
    if metric.startswith("coaptation_height_") or metric == "central_coaptation_height_mm":
        return (4.0, None)
    return None


# ---------------------------------------------------------------------------------------------------------
# Surgeon-facing parts (issue 19 item 5; docs/studies.md "The surgeon-facing report"): the nomograms against
# the graft diameter, the commissure-rotation panel, the stress maps of the baseline and the worst variant
# and the validation table against the published trends. They read every cycles.csv column of the last cycle
# (row["_last"]), not only the requested metrics.

# Published trends (docs/studies.md, "Validation table"). Marom et al. 2013 (finite elements, annulus 20 ->
# 30 mm): coaptation height 3.3 -> 0.3 mm, effective height 10.9 -> 8.0 mm: slopes per mm of diameter.
MAROM_COAPTATION_SLOPE = (0.3 - 3.3) / (30.0 - 20.0)
MAROM_EFFECTIVE_SLOPE = (8.0 - 10.9) / (30.0 - 20.0)
COAPTATION_BAND = (4.0, None)
EFFECTIVE_BAND = (9.0, 10.0)


def last_value(row, column):
    return number(row.get("_last", {}).get(column))


def coaptation_stats(row):
    """Mean, min and max of the per-pair coaptation heights of a row's last cycle [mm] (None when absent)."""
    vals = [number(v) for k, v in row.get("_last", {}).items()
            if k.startswith("coaptation_height_") and k.endswith("_mm")]
    vals = [v for v in vals if v is not None]
    if not vals:
        return None
    return (sum(vals) / len(vals), min(vals), max(vals))


def per_cusp_columns(row, prefix, suffix):
    """{cusp index: value} of the columns prefix<k>suffix (e.g. stress_diastole_peak_c, _kPa)."""
    out = {}
    for k, v in row.get("_last", {}).items():
        if k.startswith(prefix) and k.endswith(suffix):
            mid = k[len(prefix):len(k) - len(suffix)]
            if mid.isdigit() and number(v) is not None:
                out[int(mid)] = number(v)
    return out


def find_parameter(params, test):
    """(index, label, path, base) of the first parameter whose first path passes test(path), or None."""
    for k, p in enumerate(params):
        if test(p["paths"][0]):
            return k, p["labels"][0], p["paths"][0], p.get("base")
    return None


def fit_slope(points):
    """Least-squares slope of (x, y) points; None with fewer than two distinct x."""
    pts = [(x, y) for x, y in points if x is not None and y is not None]
    if len(set(x for x, _ in pts)) < 2:
        return None
    n = len(pts)
    mx = sum(x for x, _ in pts) / n
    my = sum(y for _, y in pts) / n
    sxx = sum((x - mx) ** 2 for x, _ in pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sxx


def direction(slope):
    if slope is None:
        return "not measured"
    return "rises" if slope > 0 else "falls" if slope < 0 else "flat"


def verdict(simulated, expected_sign):
    """agree / disagree / not measured: the simulated slope's sign against the published one."""
    if simulated is None:
        return "not measured"
    if simulated == 0:
        return "disagree"
    return "agree" if (simulated > 0) == (expected_sign > 0) else "disagree"


def shade(ax, band):
    lo, hi = band
    if hi is None:
        top = max(lo * 1.5, ax.get_ylim()[1])
        ax.axhspan(lo, top, color="green", alpha=0.12, label="target")
        ax.set_ylim(top=top)
    else:
        ax.axhspan(lo, hi, color="green", alpha=0.15, label="target")


def diameter_mm(path, value):
    v = number(value)
    if v is None:
        return None
    return 2000.0 * v if path.endswith("annulus_radius") else 1000.0 * v


def groups_by(rows, labels):
    g = {}
    for r in rows:
        g.setdefault(tuple((l, r[l]) for l in labels), []).append(r)
    return g


def nomograms(plt, root, rows, params, diam, shape):
    """plots/nomogram.png: effective and coaptation height against the graft diameter, target bands shaded;
    one column per graft shape (straight and neo-sinus side by side) when the study sweeps graft_shape."""
    k, label, path, _ = diam
    shape_label = shape[1] if shape else None
    shapes = []
    for r in rows:
        s = r[shape_label] if shape_label else "all"
        if s not in shapes:
            shapes.append(s)
    other = [l for j, p in enumerate(params) if j != k and (not shape or j != shape[0]) for l in p["labels"][:1]]
    fig, axes = plt.subplots(2, len(shapes), figsize=(4.6 * len(shapes), 6.4), squeeze=False, sharey="row")
    for c, s in enumerate(shapes):
        members = [r for r in rows if (r[shape_label] if shape_label else "all") == s]
        for key, grp in groups_by(members, other).items():
            name = ", ".join("%s=%s" % kv for kv in key) or None
            eff = sorted((diameter_mm(path, r[label]), last_value(r, "effective_height_mm")) for r in grp)
            eff = [p for p in eff if p[0] is not None and p[1] is not None]
            if eff:
                axes[0][c].plot([p[0] for p in eff], [p[1] for p in eff], "o-", label=name)
            co = []
            for r in grp:
                st = coaptation_stats(r)
                x = diameter_mm(path, r[label])
                if st is not None and x is not None:
                    co.append((x, st))
            co.sort()
            if co:
                ys = [st[0] for _, st in co]
                err = [[st[0] - st[1] for _, st in co], [st[2] - st[0] for _, st in co]]
                axes[1][c].errorbar([x for x, _ in co], ys, yerr=err, fmt="o-", capsize=3, label=name)
        for row_i, (metric, band) in enumerate((("effective height [mm]", EFFECTIVE_BAND),
                                                ("coaptation height [mm] (mean of the lines, bars: range)",
                                                 COAPTATION_BAND))):
            ax = axes[row_i][c]
            if not ax.lines and not ax.collections:
                ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes,
                        color="gray")
            shade(ax, band)
            ax.set_xlabel("graft diameter [mm]" if path.endswith("graft_diameter") else "annulus diameter [mm]")
            ax.set_ylabel(metric, fontsize=8)
            ax.set_title(("graft shape: %s" % s) if shape_label else metric.split(" [")[0], fontsize=9)
            ax.grid(True, alpha=0.3)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(root, "plots", "nomogram.png"), dpi=90)
    plt.close(fig)
    return "plots/nomogram.png"


def rotation_delta(row, rot):
    _, label, _, base = rot
    v = number(row[label])
    b = number(base)
    if v is None:
        return None
    return v - b if b is not None else v


def rotation_panel(plt, root, rows, rot, params):
    """plots/commissure_rotation.png: per-cusp effective height, diastolic stress and the gap areas against
    delta (the commissure's angle minus the base scene's). When other parameters are swept too, the variants
    with the first variant's values of them (named in the title)."""
    other = [p["labels"][0] for j, p in enumerate(params) if j != rot[0]]
    if other and rows:
        key = [(l, rows[0][l]) for l in other]
        rows = [r for r in rows if all(r[l] == v for l, v in key)]
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 3.8), squeeze=False)
    if other:
        fig.suptitle("at " + ", ".join("%s = %s" % kv for kv in key), fontsize=9)
    axes = axes[0]
    pts = sorted(((rotation_delta(r, rot), r) for r in rows if rotation_delta(r, rot) is not None),
                 key=lambda p: p[0])
    xs = [d for d, _ in pts]

    def line(ax, values, style, name):
        p = [(x, v) for x, v in zip(xs, values) if v is not None]
        if p:
            ax.plot([a for a, _ in p], [b for _, b in p], style, label=name)

    cusps = sorted(set(c for _, r in pts for c in per_cusp_columns(r, "effective_height_c", "_mm")))
    for c in cusps:
        line(axes[0], [per_cusp_columns(r, "effective_height_c", "_mm").get(c) for _, r in pts], "o-",
             "cusp %d" % c)
    line(axes[0], [last_value(r, "effective_height_mm") for _, r in pts], "k--", "valve (central)")
    shade(axes[0], EFFECTIVE_BAND)
    axes[0].set_ylabel("effective height [mm]")
    cusps = sorted(set(c for _, r in pts for c in per_cusp_columns(r, "stress_diastole_peak_c", "_kPa")))
    for c in cusps:
        line(axes[1], [per_cusp_columns(r, "stress_diastole_peak_c", "_kPa").get(c) for _, r in pts], "o-",
             "cusp %d peak" % c)
        line(axes[1], [per_cusp_columns(r, "stress_diastole_p95_c", "_kPa").get(c) for _, r in pts], "x:",
             "cusp %d p95" % c)
    if not cusps:
        line(axes[1], [last_value(r, "stress_diastole_peak_kPa") for _, r in pts], "o-", "all cusps peak")
    axes[1].set_ylabel("diastolic von Mises stress [kPa]")
    line(axes[2], [last_value(r, "central_gap_area_mm2") for _, r in pts], "ko-", "central")
    comms = sorted(set(c for _, r in pts for c in per_cusp_columns(r, "commissural_gap_area_c", "_mm2")))
    for c in comms:
        line(axes[2], [per_cusp_columns(r, "commissural_gap_area_c", "_mm2").get(c) for _, r in pts], "o-",
             "commissure %d" % c)
    axes[2].set_ylabel("gap area at peak diastolic load [mm$^2$]")
    for ax in axes:
        if not ax.lines:
            ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes, color="gray")
        ax.set_xlabel("commissure rotation delta [deg]")
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(root, "plots", "commissure_rotation.png"), dpi=90)
    plt.close(fig)
    return "plots/commissure_rotation.png"


def read_vtp(path):
    """The ascii DataArrays of a VTK PolyData file written by `aortasph run --vtk`: {name: [rows]}; the
    points are 'Points'."""
    import re
    with open(path) as f:
        text = f.read()
    arrays = {}
    for attrs, body in re.findall(r"<DataArray([^>]*)>(.*?)</DataArray>", text, re.S):
        m = re.search(r'Name="([^"]*)"', attrs)
        name = m.group(1) if m else "Points"
        comps = re.search(r'NumberOfComponents="(\d+)"', attrs)
        nc = int(comps.group(1)) if comps else 1
        vals = [float(v) for v in body.split()]
        arrays[name] = [vals[i:i + nc] for i in range(0, len(vals), nc)] if nc > 1 else vals
    return arrays


def last_vtp(vdir):
    """The last file particles.pvd lists in VDIR/vtk, or None."""
    import re
    pvd = os.path.join(vdir, "vtk", "particles.pvd")
    try:
        with open(pvd) as f:
            files = re.findall(r'file="([^"]+)"', f.read())
    except OSError:
        return None
    return os.path.join(vdir, "vtk", files[-1]) if files else None


def leaflet_bodies(scene):
    """Indices of the scene's deformable (elastic or shell) bodies: the leaflets."""
    materials = scene.get("materials", {})
    out = []
    for i, body in enumerate(scene.get("bodies", [])):
        m = materials.get(body.get("material"), {}) if isinstance(materials, dict) else {}
        if m.get("type") in ("elastic", "shell"):
            out.append(i)
    return out


def worst_variant(rows):
    """The variant with the largest diastolic peak stress (per cusp if measured, else over all cusps; else the
    systolic peak), and the metric used; (None, None) when no stress is measured."""
    best, which, what = None, None, None
    for key in ("stress_diastole_peak_c", "stress_diastole_peak_kPa", "stress_systole_peak_kPa"):
        for r in rows:
            if key.endswith("_c"):
                vals = list(per_cusp_columns(r, key, "_kPa").values())
                v = max(vals) if vals else None
            else:
                v = last_value(r, key)
            if v is not None and (best is None or v > best):
                best, which, what = v, r, key
        if which is not None:
            return which, "%s (%.4g kPa)" % (what.rstrip("_c") + ("_*_kPa" if what.endswith("_c") else ""), best)
    return None, None


def stress_maps(plt, root, rows, runs, baseline, worst):
    """plots/stress_map_<id>.png for the baseline and the worst variant: the leaflet particles of the last VTK
    frame coloured by von Mises stress (top and side views, one colour range for both variants); else the
    run's rendered figure sheets. Returns [(id, role, html)]."""
    e = html.escape
    chosen = [(baseline, "baseline")] + ([(worst, "worst")] if worst is not None and worst is not baseline else [])
    data = {}
    for r, _ in chosen:
        vdir = os.path.join(root, "variants", r["id"])
        f = last_vtp(vdir)
        scene = runs.get(r["id"], {}).get("scene", {})
        if f is None or plt is None:
            continue
        try:
            a = read_vtp(f)
        except (OSError, ValueError):
            continue
        if "von_mises" not in a or "body" not in a:
            continue
        keep = set(leaflet_bodies(scene))
        pts = [(p, s) for p, b, s in zip(a["Points"], a["body"], a["von_mises"]) if int(b) in keep]
        if pts:
            data[r["id"]] = (os.path.basename(f), pts)
    vmax = max((s for _, pts in data.values() for _, s in pts), default=1.0) or 1.0
    out = []
    for r, role in chosen:
        vid = r["id"]
        if vid in data:
            name, pts = data[vid]
            fig, axes = plt.subplots(1, 2, figsize=(9, 4))
            xs = [p[0] * 1e3 for p, _ in pts]
            ys = [p[1] * 1e3 for p, _ in pts]
            zs = [p[2] * 1e3 for p, _ in pts]
            cs = [s / 1e3 for _, s in pts]
            for ax, (h, v, hl, vl) in zip(axes, ((xs, zs, "x [mm]", "z [mm]"), (xs, ys, "x [mm]", "y [mm] (axis)"))):
                sc = ax.scatter(h, v, c=cs, s=6, cmap="inferno", vmin=0, vmax=vmax / 1e3)
                ax.set_aspect("equal")
                ax.set_xlabel(hl)
                ax.set_ylabel(vl)
            axes[0].set_title("from the aorta (top)", fontsize=9)
            axes[1].set_title("side", fontsize=9)
            fig.colorbar(sc, ax=list(axes), label="von Mises [kPa]")
            fig.suptitle("%s (%s): %s" % (vid, role, name), fontsize=9)
            png = "plots/stress_map_%s.png" % vid
            fig.savefig(os.path.join(root, png), dpi=90)
            plt.close(fig)
            out.append((vid, role, "<img src='%s' alt='stress map %s'>" % (e(png), e(vid))))
            continue
        fig_dir = os.path.join(root, "variants", vid, "figures")
        sheets = sorted(p for p in os.listdir(fig_dir) if p.endswith(".png") and p != "wiggers.png") \
            if os.path.isdir(fig_dir) else []
        if sheets:
            out.append((vid, role, "".join("<p>%s (the run's figure sheet; no VTK frame with stresses)<br>"
                                           "<img src='variants/%s/figures/%s' alt='%s'></p>" %
                                           (e(p), e(vid), e(p), e(p)) for p in sheets)))
        else:
            out.append((vid, role, "<p>no VTK frame (run with --vtk) and no rendered figure sheet</p>"))
    return out


def validation_rows(rows, params, diam, shape, rot, height):
    """The validation table: per published trend, the simulated direction and slope, and the verdict."""
    out = []

    def row(sweep, metric, published, pub_slope, sim_slope, sim_text, v, note=""):
        out.append({"sweep": sweep, "metric": metric, "published": published,
                    "published_slope": "" if pub_slope is None else "%.4g" % pub_slope,
                    "simulated": sim_text, "simulated_slope": "" if sim_slope is None else "%.4g" % sim_slope,
                    "verdict": v, "note": note})

    if diam:
        k, label, path, _ = diam
        shape_label = shape[1] if shape else None
        by_shape = groups_by(rows, [shape_label] if shape_label else [])
        for key, grp in by_shape.items():
            where = " (%s)" % key[0][1] if key else ""
            sweep = ("graft" if path.endswith("graft_diameter") else "annulus") + " diameter" + where
            for metric, pub, expected in (("coaptation height", MAROM_COAPTATION_SLOPE, "falls 3.3 -> 0.3 mm"),
                                          ("effective height", MAROM_EFFECTIVE_SLOPE, "falls 10.9 -> 8.0 mm")):
                pts = []
                for r in grp:
                    x = diameter_mm(path, r[label])
                    if metric == "coaptation height":
                        st = coaptation_stats(r)
                        pts.append((x, st[0] if st else None))
                    else:
                        pts.append((x, last_value(r, "effective_height_mm")))
                s = fit_slope(pts)
                row(sweep, metric + " [mm per mm]", "Marom et al. 2013: %s as the annulus grows 20 -> 30 mm" % expected,
                    pub, s, direction(s), verdict(s, pub),
                    "FE, annulus diameter; here the %s" % ("graft" if path.endswith("graft_diameter") else "annulus"))
    if shape:
        _, slabel, _, _ = shape
        other = [l for j, p in enumerate(params) if j != shape[0] for l in p["labels"][:1]]
        pairs = []
        for key, grp in groups_by(rows, other).items():
            st = [r for r in grp if r[slabel] == "straight"]
            ns = [r for r in grp if r[slabel] == "neo_sinus"]
            if st and ns:
                pairs.append((st[0], ns[0]))
        for metric, col, sign, text in (
                ("closing time [ms]", "closing_time_ms", -1, "without sinuses the leaflets close faster"),
                ("diastolic peak stress [kPa]", "stress_diastole_peak_kPa", +1,
                 "without sinuses the leaflets carry more stress")):
            diffs = [last_value(a, col) - last_value(b, col) for a, b in pairs
                     if last_value(a, col) is not None and last_value(b, col) is not None]
            mean = sum(diffs) / len(diffs) if diffs else None
            sim = ("straight - neo-sinus = %.4g (mean of %d pairs)" % (mean, len(diffs))) if diffs else "not measured"
            row("graft shape", metric, "Katayama et al. 2008: " + text, None, None, sim, verdict(mean, sign),
                "qualitative (porcine / FE); sign of straight - neo-sinus")
    if height:
        _, hlabel, _, base = height
        b = number(base)
        pts = []
        for r in rows:
            x = number(r[hlabel])
            if x is not None and b:
                x = x / b
            st = coaptation_stats(r)
            pts.append((x, st[0] if st else None, r))
        s = fit_slope([(x, y) for x, y, _ in pts])
        row("commissure height (factor of the base)", "coaptation height [mm per unit factor]",
            "lower commissures lower the coaptation (issue 19)", None, s, direction(s), verdict(s, +1),
            "direction only")
        low = [p for p in pts if p[0] is not None and abs(p[0] - 0.8) < 0.051]
        ref = [p for p in pts if p[0] is not None and abs(p[0] - 1.0) < 1e-6]
        leak = None
        if low and ref:
            def lk(r):
                for c in ("regurgitant_fraction_pct", "leakage_volume_ml"):
                    if last_value(r, c) is not None:
                        return c, last_value(r, c)
                return None, None
            c0, v0 = lk(ref[0][2])
            c1, v1 = lk(low[0][2])
            gap = last_value(low[0][2], "central_gap_area_mm2")
            if c0 is not None and c0 == c1:
                leak = v1 - v0
                sim = "%s x0.8 - x1.0 = %.4g%s" % (c0, leak, "" if gap is None else "; central gap at x0.8 %.4g mm2" % gap)
            else:
                sim = "not measured"
        else:
            sim = "not measured (no x0.8 and x1.0 variants)"
        row("commissure height (factor of the base)", "leakage at x0.8",
            "in vitro: commissures lowered by 20 % leak", None, None, sim, verdict(leak, +1),
            "more regurgitation at x0.8 than at x1.0")
    if rot:
        for metric, col in (("effective height [mm per deg]", "effective_height_mm"),
                            ("diastolic peak stress [kPa per deg]", "stress_diastole_peak_kPa")):
            s = fit_slope([(rotation_delta(r, rot), last_value(r, col)) for r in rows])
            row("commissure rotation delta", metric, "no published study (issue 19: first rotation study)",
                None, s, direction(s), "no published value")
    return out


def baseline_variant(rows, params):
    """The variant whose swept values are all the base scene's own (the first variant when none is)."""
    for r in rows:
        same = True
        for p in params:
            b, v = p.get("base"), r[p["labels"][0]]
            if b is None:
                same = False
            elif isinstance(b, (int, float)) and not isinstance(b, bool):
                same = same and number(v) is not None and abs(number(v) - b) <= 1e-9 * max(1.0, abs(b))
            else:
                same = same and str(b) == v
        if same:
            return r
    return rows[0] if rows else None


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: study_report.py DIR")
    root = sys.argv[1]
    with open(os.path.join(root, "study.json")) as f:
        study = json.load(f)
    table = read_csv_rows(os.path.join(root, "variants.csv"))
    labels = table[0][1:]
    variants = [(row[0], row[1:]) for row in table[1:]]
    metrics = study["metrics"]

    rows, runs = [], {}
    for vid, values in variants:
        d = os.path.join(root, "variants", vid)
        run = {}
        try:
            with open(os.path.join(d, "run.json")) as f:
                run = json.load(f)
        except (OSError, ValueError):
            pass
        runs[vid] = run
        last = {}
        cycles = 0
        try:
            c = read_csv_rows(os.path.join(d, "cycles.csv"))
            if len(c) > 1:
                last = dict(zip(c[0], c[-1]))
                cycles = len(c) - 1
        except OSError:
            pass
        spacing = run.get("scene", {}).get("resolution", {}).get("spacing")
        row = {"id": vid, "status": run.get("status", "missing"), "cycles": cycles,
               "spacing_mm": "%g" % (spacing * 1000) if isinstance(spacing, (int, float)) else ""}
        row.update(zip(labels, values))
        row["_last"] = last
        for m in metrics:
            v = last.get(m, "")
            row[m] = "" if v.lower() == "nan" else v
        rows.append(row)

    header = ["id"] + labels + ["spacing_mm", "status", "cycles"] + metrics
    with open(os.path.join(root, "metrics.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        for r in rows:
            w.writerow([r[h] for h in header])

    # Plots: per swept parameter, each metric against it (one line per combination of the other parameters).
    plots = []
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        plt = None
        print("study_report.py: warning: no matplotlib (apt-get install python3-matplotlib): no plots",
              file=sys.stderr)
    os.makedirs(os.path.join(root, "plots"), exist_ok=True)
    if plt is not None:
        # A zipped parameter (several paths set together) is plotted against its first path; the lines are the
        # combinations of the other parameters.
        params = [p.get("labels", [p.get("label")]) for p in study["parameters"]]
        for k, plabels in enumerate(params):
            label = plabels[0]
            others = [l for j, pl in enumerate(params) if j != k for l in pl]
            xs_all = [r[label] for r in rows]
            numeric = all(number(x) is not None for x in xs_all)
            order = sorted(set(xs_all), key=lambda x: number(x) if numeric else xs_all.index(x))
            groups = {}
            for r in rows:
                key = tuple((l, r[l]) for l in others)
                groups.setdefault(key, []).append(r)
            n = len(metrics)
            cols = min(3, n)
            nrows = (n + cols - 1) // cols
            fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.2 * nrows), squeeze=False)
            for i, m in enumerate(metrics):
                ax = axes[i // cols][i % cols]
                drawn = False
                for key, members in groups.items():
                    pts = [((number(r[label]) if numeric else order.index(r[label])), number(r[m])) for r in members]
                    pts = sorted(p for p in pts if p[1] is not None)
                    if pts:
                        drawn = True
                        name = ", ".join("%s=%s" % kv for kv in key) or None
                        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=name)
                band = target_of(m)
                if band is not None:
                    lo, hi = band
                    if hi is None:
                        ax.axhline(lo, color="green", lw=0.8, ls="--")
                        ax.axhspan(lo, max(lo * 1.5, ax.get_ylim()[1]), color="green", alpha=0.12, label="target")
                    else:
                        ax.axhspan(lo, hi, color="green", alpha=0.15, label="target")
                if not drawn:
                    ax.text(0.5, 0.5, "not measured (empty in cycles.csv)", ha="center", va="center",
                            transform=ax.transAxes, fontsize=8, color="gray")
                if not numeric:
                    ax.set_xticks(range(len(order)))
                    ax.set_xticklabels(order, rotation=30, fontsize=7)
                ax.set_xlabel(label, fontsize=8)
                ax.set_title(m, fontsize=9)
                ax.grid(True, alpha=0.3)
                if len(groups) > 1 and i == 0:
                    ax.legend(fontsize=6)
            for i in range(n, nrows * cols):
                axes[i // cols][i % cols].axis("off")
            fig.tight_layout()
            name = "plots/parameter_%d.png" % k
            fig.savefig(os.path.join(root, name), dpi=90)
            plt.close(fig)
            plots.append((" + ".join(plabels), name))

    # The surgeon-facing parts: which sweeps the study has.
    import re
    sparams = study["parameters"]
    diam = find_parameter(sparams, lambda p: p in ("aortic_root.graft_diameter", "aortic_root.annulus_radius"))
    shape = find_parameter(sparams, lambda p: p == "aortic_root.graft_shape")
    rot = find_parameter(sparams, lambda p: re.fullmatch(r"aortic_root\.commissure_angles\.\d+", p) is not None)
    height = find_parameter(sparams, lambda p: p == "aortic_root.commissure_height")
    nomogram = rotation = None
    if plt is not None and diam:
        nomogram = nomograms(plt, root, rows, sparams, diam, shape)
    if plt is not None and rot:
        rotation = rotation_panel(plt, root, rows, rot, sparams)
    base_row = baseline_variant(rows, sparams)
    worst_row, worst_why = worst_variant(rows)
    maps = stress_maps(plt, root, rows, runs, base_row, worst_row) if base_row is not None else []
    validation = validation_rows(rows, sparams, diam, shape, rot, height)
    vheader = ["sweep", "metric", "published", "published_slope", "simulated", "simulated_slope", "verdict",
               "note"]
    with open(os.path.join(root, "validation.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(vheader)
        for v in validation:
            w.writerow([v[h] for h in vheader])

    # The header: the model as the variants ran it (their run.json scenes).
    models, bcs = {}, {}
    for vid, run in runs.items():
        scene = run.get("scene")
        if scene:
            models.setdefault(leaflet_model(scene), []).append(vid)
            bcs.setdefault(tuple(boundary_conditions(scene)), []).append(vid)
    spacings = sorted(set(r["spacing_mm"] for r in rows if r["spacing_mm"]), key=float)

    e = html.escape
    out = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>%s</title>" % e(study["title"]),
           "<style>body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;font-size:12px}"
           "td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}th{background:#eee}"
           ".bad{background:#fcc}.good{background:#cfc}img{max-width:100%}</style></head><body>",
           "<h1>%s</h1>" % e(study["title"]), "<p>%s</p>" % e(study.get("description", ""))]
    out.append("<h2>Model</h2><ul>")
    out.append("<li>Base scene: <code>%s</code>; fixed settings: <code>%s</code></li>" %
               (e(study["scene"]), e(" ".join(study.get("fixed", [])) or "none")))
    for text, vids in models.items():
        which = "" if len(models) == 1 else " (variants %s)" % ", ".join(vids)
        out.append("<li>Leaflet model%s: %s</li>" % (which, e(text)))
    for items, vids in bcs.items():
        which = "" if len(bcs) == 1 else " (variants %s)" % ", ".join(vids)
        out.append("<li>Boundary conditions%s: %s</li>" % (which, e("; ".join(items))))
    out.append("<li>Resolution: particle spacing %s mm. Coaptation heights and gaps are resolved to about one "
               "spacing; the metrics are those of the last simulated cycle (docs/valve-metrics.md). Clinical "
               "comparisons need the physiological (pressure-driven) cycle and thin-shell leaflets; with a "
               "velocity inlet and a pressure outlet the gradients and diastolic loads are not "
               "physiological.</li>" % e(", ".join(spacings) or "unknown"))
    out.append("</ul>")

    out.append("<h2>Variants</h2><p><a href='metrics.csv'>metrics.csv</a>. Green / red cells: inside / outside "
               "the clinical target (effective height 9&ndash;10 mm, coaptation height &ge; 4 mm); red rows: "
               "runs that did not end with status ok.</p><table><tr>")
    out += ["<th>%s</th>" % e(h) for h in header]
    out.append("</tr>")
    for r in rows:
        cls = "" if r["status"] == "ok" else " class='bad'"
        cells = []
        for h in header:  # 4 significant digits here; metrics.csv keeps every digit
            v = number(r[h]) if h not in ("id", "status", "cycles") else None
            text = r[h] if v is None else "%.4g" % v
            band = target_of(h) if h in metrics else None
            light = ""
            if band is not None and v is not None:  # traffic light: inside the target band or not
                ok = v >= band[0] and (band[1] is None or v <= band[1])
                light = " class='%s'" % ("good" if ok else "bad")
            cells.append("<td%s>%s</td>" % (light, e(str(text))))
        out.append("<tr%s>" % cls + "".join(cells) + "</tr>")
    out.append("</table>")

    if plt is None:
        out.append("<p>No plots: this python has no matplotlib.</p>")
    if plots:
        out.append("<h2>Metrics against the swept parameters</h2>")
        for label, name in plots:
            out.append("<h3>%s</h3><img src='%s' alt='%s'>" % (e(label), e(name), e(label)))

    out.append("<h2>Nomograms: effective and coaptation height against the graft diameter</h2>")
    if nomogram:
        out.append("<p>Target bands shaded: effective height 9&ndash;10 mm (Sch&auml;fers et al. 2006), "
                   "coaptation height &ge; 4 mm; coaptation height: the mean of the coaptation lines, bars "
                   "their range.%s</p><img src='%s' alt='nomogram'>" %
                   (" Straight and neo-sinus grafts side by side." if shape else "", e(nomogram)))
    else:
        out.append("<p>not applicable: the study does not sweep the graft (or annulus) diameter%s.</p>" %
                   ("" if plt is not None else " / no matplotlib"))
    if rot:
        out.append("<h2>Commissure rotation</h2>")
        if rotation:
            out.append("<p>delta = %s minus the base scene's value (%s). Cusp k is the leaflet of sector k "
                       "(from commissure k to the next); stresses in diastole (peak and 95th percentile); gap "
                       "areas at peak diastolic load (docs/valve-metrics.md).</p><img src='%s' alt='rotation'>"
                       % (e(rot[2]), e(str(rot[3])), e(rotation)))
        else:
            out.append("<p>No plots: this python has no matplotlib.</p>")
    out.append("<h2>Stress maps: baseline and worst variant</h2>")
    if worst_row is not None:
        out.append("<p>Worst variant: %s, by %s.</p>" % (e(worst_row["id"]), e(worst_why)))
    else:
        out.append("<p>No leaflet stress measured: the worst variant is not defined.</p>")
    for vid, role, frag in maps:
        out.append("<h3>%s (%s)</h3>%s" % (e(vid), e(role), frag))
    out.append("<h2>Validation against the published trends</h2><p><a href='validation.csv'>validation.csv</a>. "
               "Literature values are porcine or finite-element numbers: compare directions and slopes, not "
               "values.</p>")
    if validation:
        out.append("<table><tr>" + "".join("<th>%s</th>" % e(h) for h in vheader) + "</tr>")
        for v in validation:
            cls = {"agree": " class='good'", "disagree": " class='bad'"}.get(v["verdict"], "")
            out.append("<tr>" + "".join("<td%s>%s</td>" % (cls if h == "verdict" else "", e(v[h]))
                                        for h in vheader) + "</tr>")
        out.append("</table>")
    else:
        out.append("<p>No sweep of this study has a published counterpart (graft or annulus diameter, graft "
                   "shape, commissure height, commissure rotation).</p>")

    out.append("<h2>Variants: Wiggers plots and figure sheets</h2>")
    for r in rows:
        vid = r["id"]
        fig_dir = os.path.join(root, "variants", vid, "figures")
        pngs = sorted(p for p in os.listdir(fig_dir) if p.endswith(".png")) if os.path.isdir(fig_dir) else []
        settings = ", ".join("%s = %s" % (l, r[l]) for l in labels)
        out.append("<h3>%s: %s</h3>" % (e(vid), e(settings)))
        if not pngs:
            out.append("<p>no figures</p>")
        for p in (["wiggers.png"] if "wiggers.png" in pngs else []) + [p for p in pngs if p != "wiggers.png"]:
            src = "variants/%s/figures/%s" % (vid, p)
            out.append("<p>%s<br><img src='%s' alt='%s'></p>" % (e(p), e(src), e(p)))
    out.append("</body></html>")
    with open(os.path.join(root, "report.html"), "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
