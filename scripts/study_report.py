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
