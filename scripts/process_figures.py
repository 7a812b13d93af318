#!/usr/bin/env python3
"""Draws docs/process.md's two figures from real runs (no number is typed in here):

* docs/images/orient-candidates.svg: the orientation candidates of a shared model
  (`cargo run --release --example orient_time`), their unsupported area and height;
* docs/images/predicted-density.svg: the predicted density of the 20 mm cube by
  droplet_aspect, stagger off and on (`dropslice --report`, `part.predicted_density`).

    python3 scripts/process_figures.py      (after cargo build --release)
"""
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = os.path.join(ROOT, "..", "shared", "models")
CLI = os.path.join(ROOT, "target", "release", "dropslice")
OUT = os.path.join(ROOT, "docs", "images")
FONT = 'font-family="sans-serif" font-size="12"'


def esc(s):
    return s.replace("&", "&amp;").replace("<", "&lt;")


def orient_figure(model):
    subprocess.run(["cargo", "build", "--release", "--example", "orient_time", "-q"], cwd=ROOT, check=True)
    exe = os.path.join(ROOT, "target", "release", "examples", "orient_time")
    out = subprocess.run([exe, os.path.join(MODELS, model), "1"], capture_output=True, text=True, check=True)
    o = json.loads(out.stdout)
    cands = o["candidates"][:14]
    cur = o["current"]
    worst = max(c["unsupported_area"] for c in cands + [cur]) or 1.0
    row, left, width = 22, 280, 360
    h = 60 + row * (len(cands) + 1) + 30
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{left + width + 140}" height="{h}" {FONT}>',
           '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="10" y="20" font-size="14" font-weight="bold">Orientation candidates of {esc(model)} '
           f'(best {len(cands)} of {len(o["candidates"])}, best first)</text>',
           f'<text x="10" y="40">bar: unsupported area by the overhang rule, from the facets (mm²); right: the part\'s height</text>']
    def bar(i, c, label, colour):
        y = 55 + i * row
        w = width * c["unsupported_area"] / worst
        svg.append(f'<text x="10" y="{y + 14}">{esc(label)}</text>')
        svg.append(f'<rect x="{left}" y="{y + 3}" width="{max(w, 1):.1f}" height="{row - 8}" fill="{colour}"/>')
        svg.append(f'<text x="{left + max(w, 1) + 6:.1f}" y="{y + 14}">{c["unsupported_area"]:.1f} mm², {c["height"]:.1f} mm</text>')
    def rot(c):
        r = lambda v: f"{round(v, 2) + 0.0:g}"
        return f"rotate_x {r(c['rotate_x'])}°, rotate_y {r(c['rotate_y'])}°"
    for i, c in enumerate(cands):
        bar(i, c, ("chosen: " if i == 0 else f"{i + 1}. ") + rot(c), "#2a7" if i == 0 else "#8ab")
    bar(len(cands), cur, "current: " + rot(cur), "#c55")
    svg.append("</svg>")
    path = os.path.join(OUT, "orient-candidates.svg")
    with open(path, "w") as f:
        f.write("\n".join(svg) + "\n")
    print("wrote", path)


def density_figure():
    aspects = [0.9, 0.95, 1.0, 1.04, 1.1, 1.15, 1.2, 1.3]
    series = {}
    with tempfile.TemporaryDirectory() as d:
        for stagger in ("false", "true"):
            pts = []
            for a in aspects:
                rep = os.path.join(d, "r.json")
                subprocess.run([CLI, os.path.join(MODELS, "cube_20mm_ascii.stl"), "-q", "-o", os.path.join(d, "c.gco"),
                                "--report", rep, "--set", f"droplet_aspect={a}", "--set", f"stagger={stagger}"], check=True)
                with open(rep) as f:
                    pts.append((a, json.load(f)["part"]["predicted_density"]))
            series[stagger] = pts
    lo = min(p[1] for s in series.values() for p in s)
    lo = max(0.0, (int(lo) // 5) * 5.0)
    hi = 100.0
    x0, y0, w, h = 60, 40, 480, 260
    X = lambda a: x0 + w * (a - aspects[0]) / (aspects[-1] - aspects[0])
    Y = lambda v: y0 + h * (hi - v) / (hi - lo)
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{x0 + w + 170}" height="{y0 + h + 50}" {FONT}>',
           '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="10" y="20" font-size="14" font-weight="bold">Predicted density of the 20 mm cube (defaults but droplet_aspect, stagger)</text>',
           f'<line x1="{x0}" y1="{y0 + h}" x2="{x0 + w}" y2="{y0 + h}" stroke="black"/>',
           f'<line x1="{x0}" y1="{y0}" x2="{x0}" y2="{y0 + h}" stroke="black"/>',
           f'<text x="{x0 + w / 2 - 50}" y="{y0 + h + 38}">droplet_aspect (B / H)</text>']
    v = lo
    while v <= hi + 1e-9:
        svg.append(f'<line x1="{x0 - 4}" y1="{Y(v):.1f}" x2="{x0 + w}" y2="{Y(v):.1f}" stroke="#ddd"/>')
        svg.append(f'<text x="{x0 - 40}" y="{Y(v) + 4:.1f}">{v:.0f} %</text>')
        v += 5
    for a in aspects:
        svg.append(f'<text x="{X(a) - 12:.1f}" y="{y0 + h + 18}">{a:g}</text>')
    colours = {"false": "#c55", "true": "#27a"}
    names = {"false": "stagger off", "true": "stagger on"}
    for k, pts in series.items():
        path = " ".join(f"{'M' if i == 0 else 'L'}{X(a):.1f},{Y(v):.1f}" for i, (a, v) in enumerate(pts))
        svg.append(f'<path d="{path}" fill="none" stroke="{colours[k]}" stroke-width="2"/>')
        for a, v in pts:
            svg.append(f'<circle cx="{X(a):.1f}" cy="{Y(v):.1f}" r="3" fill="{colours[k]}"/>')
        a, v = pts[-1]
        svg.append(f'<text x="{X(a) + 8:.1f}" y="{Y(v) + 4:.1f}" fill="{colours[k]}">{names[k]}</text>')
    svg.append("</svg>")
    path = os.path.join(OUT, "predicted-density.svg")
    with open(path, "w") as f:
        f.write("\n".join(svg) + "\n")
    print("wrote", path)
    for k, pts in series.items():
        print(names[k], ", ".join(f"{a:g}: {v:.1f} %" for a, v in pts))


if __name__ == "__main__":
    orient_figure(sys.argv[1] if len(sys.argv) > 1 else "extruder_idler.stl")
    density_figure()
