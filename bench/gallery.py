#!/usr/bin/env python3
"""One HTML page per outfit: a tile per slice, the input faint under the simplified result.

    bench/gallery.py --title NAME --report OUTFIT.simplify.json --out PAGE.html [--strata BIN]

The report is the one `strata simplify FOLDER -o OUT --report R.json` writes (batch: one run
per slice, with "input", "output", and "error" for slices it skipped). Every tile is an inline
SVG: the input's layers thin and faint, the result's layers in colour on top, and a red ring
around every crossing (`strata check --json` of the result, or of the input when the slice was
skipped). The caption gives vertices before -> after, crossings, refusals and the smallest
separation ratio. The page has no scripts and no external files: open it in any browser.
"""
import argparse
import html
import json
import math
import os
import subprocess
import sys

PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
           "#bcbd22", "#7f7f7f", "#393b79", "#637939", "#8c6d31"]
CROSSING = "#e00000"
TILE = 300  # px


def load(path):
    with open(path) as f:
        return json.load(f)


def crossings(strata, scene_path):
    """Points where layers cross or a layer crosses itself (strata check --json)."""
    if not strata or not os.path.exists(scene_path):
        return []
    run = subprocess.run([strata, "check", "--json", scene_path], capture_output=True, text=True)
    try:
        report = json.loads(run.stdout)
    except ValueError:
        return []
    return [c["point"] for c in report.get("crossings", []) + report.get("self_crossings", [])]


def path_data(layer):
    pts = layer["points"]
    d = "M" + " L".join("%.6g %.6g" % (p[0], -p[1]) for p in pts)
    return d + (" Z" if layer.get("closed") else "")


def tile(run, strata):
    scene_in = load(run["input"])
    skipped = "error" in run or "skipped" in run
    out_path = run.get("output", "")
    scene_out = load(out_path) if not skipped and out_path and os.path.exists(out_path) else None
    xs = [p[0] for l in scene_in["layers"] for p in l["points"]]
    ys = [-p[1] for l in scene_in["layers"] for p in l["points"]]
    w, h = max(xs) - min(xs), max(ys) - min(ys)
    size = max(w, h, 1e-12)
    pad = 0.04 * size
    view = (min(xs) - pad - (size - w) / 2, min(ys) - pad - (size - h) / 2, size + 2 * pad,
            size + 2 * pad)
    marks = crossings(strata, run["input"] if skipped else out_path)
    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" viewBox="%.6g %.6g '
             '%.6g %.6g">' % ((TILE, TILE) + view)]
    parts.append('<rect x="%.6g" y="%.6g" width="%.6g" height="%.6g" fill="#ffffff"/>' % view)
    faint = 'stroke-opacity="0.3"' if scene_out else 'stroke-opacity="0.9"'
    for i, layer in enumerate(scene_in["layers"]):
        parts.append('<path d="%s" fill="none" stroke="%s" %s stroke-width="%s" '
                     'vector-effect="non-scaling-stroke"><title>%s (input)</title></path>'
                     % (path_data(layer), PALETTE[i % len(PALETTE)] if not scene_out else "#888888",
                        faint, "1" if scene_out else "1.5", html.escape(layer["name"])))
    if scene_out:
        for i, layer in enumerate(scene_out["layers"]):
            parts.append('<path d="%s" fill="none" stroke="%s" stroke-width="1.5" '
                         'vector-effect="non-scaling-stroke"><title>%s</title></path>'
                         % (path_data(layer), PALETTE[i % len(PALETTE)], html.escape(layer["name"])))
    r = 0.025 * view[2]
    for p in marks:
        parts.append('<circle class="crossing" cx="%.6g" cy="%.6g" r="%.6g" fill="none" '
                     'stroke="%s" stroke-width="2.5" vector-effect="non-scaling-stroke"/>'
                     % (p[0], -p[1], r, CROSSING))
    parts.append("</svg>")
    name = os.path.splitext(os.path.basename(run["input"]))[0]
    if skipped:
        caption = "not simplified: %s" % html.escape(str(run.get("error") or run.get("skipped")))[:160]
        status = "skipped"
    else:
        before = sum(l["before"] for l in run["layers"])
        after = sum(l["after"] for l in run["layers"])
        ratio = run.get("min_separation_ratio")
        caption = "%d &rarr; %d vertices, %d crossings, %d refused%s" % (
            before, after, run["crossings"], run["refused"],
            "" if ratio is None else ", gap ratio %.3g" % ratio)
        if "input_untangled" in run:
            caption += ", input untangled first"
        status = "ok" if run.get("collision_free") else "tangled"
    return ('<figure class="tile %s">%s<figcaption><b>%s</b><br>%s%s</figcaption></figure>'
            % (status, "".join(parts), html.escape(name), caption,
               "" if not marks else " &middot; <span class=\"x\">%d marked</span>" % len(marks)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--title", required=True)
    ap.add_argument("--report", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--strata", default="", help="strata binary, for the crossing marks")
    args = ap.parse_args()
    runs = load(args.report)

    def height(run):
        base = os.path.splitext(os.path.basename(run["input"]))[0]
        try:
            return float(base.rsplit("_", 1)[1][1:])
        except (IndexError, ValueError):
            return 0.0

    runs.sort(key=height, reverse=True)
    tiles = [tile(run, args.strata) for run in runs]
    ok = sum(1 for r in runs if "error" not in r and "skipped" not in r and r.get("collision_free"))
    skipped = sum(1 for r in runs if "error" in r or "skipped" in r)
    page = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font: 13px sans-serif; margin: 16px; background: #f4f4f4; }}
.grid {{ display: grid; grid-template-columns: repeat(auto-fill, {tile}px); gap: 10px; }}
figure {{ margin: 0; background: #fff; border: 2px solid #cfcfcf; }}
figure.skipped {{ border-color: #f0a000; }} figure.tangled {{ border-color: {red}; }}
figcaption {{ padding: 4px 6px; }} .x {{ color: {red}; }}
svg {{ display: block; }}
</style></head><body>
<h1>{title}</h1>
<p>{n} slices: {ok} simplified collision-free, {skipped} not simplified (amber border).
Faint grey: the input; in colour: the result (one colour per layer); red rings: crossings
(of the result, or of the input when the slice was skipped).</p>
<div class="grid">
{tiles}
</div></body></html>
""".format(title=html.escape(args.title), tile=TILE, red=CROSSING, n=len(runs), ok=ok,
           skipped=skipped, tiles="\n".join(tiles))
    tmp = args.out + ".tmp"
    with open(tmp, "w") as f:
        f.write(page)
    os.replace(tmp, args.out)
    print("%s: %d tiles" % (args.out, len(tiles)))


if __name__ == "__main__":
    sys.exit(main())
