#!/usr/bin/env python3
"""Grid sensitivity of the hydraulic fracture of Nilsen et al. (2017) §3 on the composite
(staircase) well (scenes/hydrofrac_composite.toml, the former scenes/hydrofrac_seed.toml).

Runs variants of the scene through the release binary and prints, for each, the number of
fractured cells, the angle of the principal axis of their centroids (degrees from x; the
largest compression is along y, 90°), the elongation (ratio of the principal standard
deviations), the reach (largest distance of a fractured centroid from the well centre) and
the wall time. Usage (from the repository root, after `cargo build --release`):

    python3 scripts/hydrofrac_sensitivity.py [OUTDIR]
"""
import csv
import json
import math
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = ROOT / "target" / "release" / "porofrac"
BASE = (ROOT / "scenes" / "hydrofrac_composite.toml").read_text()
OUT = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/hydrofrac_sensitivity")


def variant(refine=12, diagonals="alternating", tracking=15.0, perturb=0.0, stress="cell"):
    s = re.sub(r"refine = \d+", f"refine = {refine}", BASE)
    s = re.sub(r'diagonals = "\w+"', f'diagonals = "{diagonals}"', s)
    if tracking is None:
        s = re.sub(r"crack_tracking = [\d.]+.*\n", "", s)
    else:
        s = re.sub(r"crack_tracking = [\d.]+", f"crack_tracking = {tracking}", s)
    if perturb > 0:
        s = s.replace("[grid]\n", f"[grid]\nperturb = {perturb}\nseed = 3\n", 1)
    if stress == "recovered":
        s = s.replace("[physics]\n", '[physics]\nfailure_stress = "recovered"\n', 1)
    return s


def stats(out):
    rows = list(csv.DictReader(open(out / "fracture.csv")))
    pts = [(float(r["x"]), float(r["y"])) for r in rows]
    n = len(pts)
    if n == 0:
        return 0, float("nan"), float("nan"), 0.0
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts) / n
    syy = sum((p[1] - my) ** 2 for p in pts) / n
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts) / n
    ang = 0.5 * math.degrees(math.atan2(2 * sxy, sxx - syy))
    m, r = 0.5 * (sxx + syy), math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
    elong = math.sqrt((m + r) / max(m - r, 1e-300))
    reach = max(math.hypot(x - 15.0, y - 15.0) for x, y in pts)
    return n, ang, elong, reach


CASES = [
    ("alternating, 15° tracking, h = 1/8 m", dict(refine=8)),
    ("alternating, 15° tracking, h = 1/12 m (the scene)", dict()),
    ("alternating, 15° tracking, h = 1/16 m", dict(refine=16)),
    ("alternating, no tracking", dict(tracking=None)),
    ("structured, no tracking", dict(diagonals="structured", tracking=None)),
    ("structured, 15° tracking", dict(diagonals="structured")),
    ("structured, no tracking, recovered stress", dict(diagonals="structured", tracking=None, stress="recovered")),
    ("perturbed 0.25, no tracking", dict(diagonals="structured", tracking=None, perturb=0.25)),
    ("perturbed 0.25, 15° tracking", dict(diagonals="structured", perturb=0.25)),
]

print("| grid near the well | fractured cells | axis (° from x) | elongation | reach (m) | wall (s) |")
print("|---|---|---|---|---|---|")
for name, kw in CASES:
    tag = re.sub(r"\W+", "_", name)
    d = OUT / tag
    d.mkdir(parents=True, exist_ok=True)
    scene = d / "scene.toml"
    scene.write_text(variant(**kw))
    r = subprocess.run([str(BIN), "run", str(scene), "--out", str(d / "out")], capture_output=True, text=True)
    summary = json.loads((d / "out" / "summary.json").read_text())
    if r.returncode != 0:
        print(f"| {name} | error: {summary.get('status')} | | | | |")
        continue
    n, ang, el, reach = stats(d / "out")
    print(f"| {name} | {n} | {ang:.1f} | {el:.2f} | {reach:.2f} | {summary['wall_seconds']['total']:.1f} |")
    sys.stdout.flush()
