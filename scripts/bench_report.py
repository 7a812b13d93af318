#!/usr/bin/env python3
"""Summarise scripts/bench.sh's raw.tsv: median wall time, peak RSS, dropslice/peer
ratios, and the issue-5 targets (PASS / FAIL / n/a when a row is missing).

usage: bench_report.py RAW.tsv [MORE.tsv ...] [--browser BROWSER.tsv]
Rows of a later file replace the same (model, tool) rows of earlier ones, so a
dropslice-only rerun (BENCH_PEERS=0) can be combined with an earlier run's peer rows.
"""
import argparse
import csv
import statistics
from collections import defaultdict

TOOL_RANK = {"dropslice": 0, "cura": 1, "prusa": 2}


def load(paths):
    groups = defaultdict(list)
    for path in paths:
        fresh = defaultdict(list)
        for r in csv.DictReader(open(path), delimiter="\t"):
            fresh[(r["model"], r["tool"])].append(r)
        groups.update(fresh)
    stats = {}
    for k, g in groups.items():
        ok = [r for r in g if r["rc"] == "0" and r["wall_s"]]
        if not ok:
            stats[k] = {"fail": g[0]["rc"], "facets": int(g[0]["facets"]), "n": len(g)}
            continue
        walls = [float(r["wall_s"]) for r in ok]
        cpu = [float(r["user_s"]) + float(r["sys_s"]) for r in ok]
        peaks = [int(r["peak_kb"]) / 1024 for r in ok]
        stats[k] = {
            "facets": int(g[0]["facets"]),
            "layers": ok[0]["layers"],
            "wall": statistics.median(walls),
            "walls": walls,
            "cpu": statistics.median(cpu),
            "rss": max(peaks),  # the largest peak of the runs
            "gcode_mb": int(ok[0]["gcode_bytes"]) / 1e6,
            "n": len(ok),
            "failed": len(g) - len(ok),
            "load": max((float(r.get("load1") or 0) for r in ok), default=0.0),
        }
    return stats


def fmt_ratio(a, b):
    return f"{a / b:.2f}" if b else "-"


def table(stats):
    models = sorted({m for m, _ in stats}, key=lambda m: (next(s["facets"] for (mm, _), s in stats.items() if mm == m), m))
    out = ["| model | facets | layers | tool | wall s (median) | wall s (runs) | CPU s | peak RSS MB | output MB | time ds/peer | RSS ds/peer | load |",
           "|---|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|"]
    for m in models:
        tools = sorted([t for mm, t in stats if mm == m], key=lambda t: TOOL_RANK.get(t, 9))
        ds = stats.get((m, "dropslice"))
        for t in tools:
            s = stats[(m, t)]
            if "fail" in s:
                out.append(f"| {m} | {s['facets']} | - | {t} | FAIL (rc={s['fail']}) | | | | | | | |")
                continue
            rt = rr = ""
            if t != "dropslice" and ds and "fail" not in ds:
                rt, rr = fmt_ratio(ds["wall"], s["wall"]), fmt_ratio(ds["rss"], s["rss"])
            runs = "/".join(f"{w:.2f}" for w in s["walls"])
            out.append(f"| {m} | {s['facets']} | {s['layers']} | {t} | {s['wall']:.2f} | {runs} | {s['cpu']:.2f} | {s['rss']:.0f} | {s['gcode_mb']:.1f} | {rt} | {rr} | {s['load']:.1f} |")
    return "\n".join(out)


def get(stats, m, t):
    s = stats.get((m, t))
    return s if s and "fail" not in s else None


def targets(stats):
    lines = ["| target | measured | result |", "|---|---|---|"]

    def row(name, measured, ok):
        res = "n/a" if ok is None else ("PASS" if ok else "FAIL")
        lines.append(f"| {name} | {measured} | {res} |")

    for m, label in (("3DBenchy", "3DBenchy"), ("torus_1000000", "1M torus")):
        ds, cu, pr = get(stats, m, "dropslice"), get(stats, m, "cura"), get(stats, m, "prusa")
        if ds and cu:
            row(f"{label}: time <= 1/3 CuraEngine", f"{ds['wall']:.2f} s vs {cu['wall']:.2f} s = {ds['wall'] / cu['wall']:.2f}", ds["wall"] <= cu["wall"] / 3)
            row(f"{label}: peak RSS <= CuraEngine", f"{ds['rss']:.0f} MB vs {cu['rss']:.0f} MB = {ds['rss'] / cu['rss']:.2f}", ds["rss"] <= cu["rss"])
        else:
            row(f"{label}: vs CuraEngine", "missing rows", None)
        if ds and pr:
            row(f"{label}: time <= 1/10 PrusaSlicer", f"{ds['wall']:.2f} s vs {pr['wall']:.2f} s = {ds['wall'] / pr['wall']:.3f}", ds["wall"] <= pr["wall"] / 10)
        else:
            row(f"{label}: vs PrusaSlicer", "missing rows", None)
    d4 = get(stats, "torus_4000000", "dropslice")
    row("4M torus: peak RSS < 600 MB", f"{d4['rss']:.0f} MB" if d4 else "missing", (d4["rss"] < 600) if d4 else None)
    d1, dz = get(stats, "torus_1000000", "dropslice"), get(stats, "torus_1000000_z4", "dropslice")
    if d1 and dz:
        row("1M torus stretched 4x in z: peak RSS < 1.5x the 1M torus",
            f"{dz['rss']:.0f} MB vs {d1['rss']:.0f} MB = {dz['rss'] / d1['rss']:.2f}x", dz["rss"] < 1.5 * d1["rss"])
        lay = int(dz["layers"]) / max(int(d1["layers"]), 1)
        row("time linear in layers (1M torus -> 4x stretched)",
            f"layers x{lay:.1f}, time x{dz['wall'] / d1['wall']:.2f}", None)
    else:
        row("1M torus stretched 4x: memory", "missing rows", None)
    sc = [(f, get(stats, f"torus_{f}", "dropslice")) for f in (100000, 1000000, 4000000)]
    sc = [(f, s) for f, s in sc if s]
    if len(sc) >= 2:
        parts = [f"{s['facets'] / 1e6:.1f}M: {s['wall']:.2f} s ({1e6 * s['wall'] / s['facets']:.2f} us/facet), {s['rss']:.0f} MB" for f, s in sc]
        row("time linear in facets (torus 100k -> 1M -> 4M, same 150 layers)", "; ".join(parts), None)
    lines.append("")
    lines.append("(n/a: judged in docs/performance.md, not by a fixed threshold.)")
    return "\n".join(lines)


def browser(path):
    rows = [l.rstrip("\n").split("\t") for l in open(path) if l.strip()]
    if rows and rows[0][0] == "TODO":
        return "TODO: no browser timing was made: " + (rows[0][1] if len(rows[0]) > 1 else "see the script's messages")
    by = defaultdict(list)
    gaps = defaultdict(list)
    info = {}
    for r in rows:
        by[r[0]].append(float(r[2]))
        info[r[0]] = (r[3], r[4])
        if len(r) > 5:
            gaps[r[0]].append(float(r[5]))
    out = [
        "| model | layers | workers | s in the page (median) | runs | longest gap of a 16 ms timer, ms |",
        "|---|---:|---:|---:|---|---:|",
    ]
    for m, ts in by.items():
        gap = f"{max(gaps[m]):.0f}" if gaps[m] else "–"
        out.append(f"| {m} | {info[m][0]} | {info[m][1]} | {statistics.median(ts):.2f} | {'/'.join(f'{t:.2f}' for t in ts)} | {gap} |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("raw", nargs="+")
    ap.add_argument("--browser")
    a = ap.parse_args()
    stats = load(a.raw)
    print("## Results (median of the timed runs; peak RSS = largest of the runs;")
    print("CPU s = user + sys, median; load = highest 1-min load average seen before a run)\n")
    print(table(stats))
    print("\n## Targets\n")
    print(targets(stats))
    if a.browser:
        print("\n## Browser (headless Chromium; the page's clock from the file chosen to every layer's G-code ready)\n")
        print(browser(a.browser))


if __name__ == "__main__":
    main()
