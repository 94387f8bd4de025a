#!/usr/bin/env python3
"""The limits of the fault area of a fault-propagation run (Renouf et al. (2006) §5.3,
Fig. 12: "the left limit separates the structure governed by a rigid motion from the
other part; the right limit separates the undeformed structure from the other part"),
from the last particle frame of a `porofrac run` of model nscd with `[nscd.fault]`.

    python3 scripts/nscd_fault_limits.py RUN_DIR [RUN_DIR ...]

For each run: the scene copy next to it (RUN_DIR.toml, as scripts/nscd_fault_variants.sh
leaves it) gives the tip, dip, slip rate and window; the last vtk/particles_NNNN.vtp
gives centres and displacements; summary.json the end time and θ_l of the summary. Over
the particles of the window, in bands of 4 r_max above the current tip (the summary's
construction, `porofrac_particles::fault::limit_angle`), the boundary between two classes
of displacement is the step that misclassifies fewest particles, and a least-squares line
through the band boundaries gives an angle from the horizontal (footwall side):

* half   — |u| ≥ s/2 against the rest: the summary's θ_l (checked against it);
* left   — |u| ≥ (1 − f) s (moving with the hanging wall) against the rest;
* right  — |u| ≥ f s (moved at all) against the undeformed rest;
* apex   — left − right: the opening of the fault area (2 φ_a of a trishear zone).

f = 0.2. Prints one Markdown row per run.
"""
import base64
import glob
import json
import math
import re
import struct
import sys
import tomllib

F = 0.2


def arrays(path):
    text = open(path).read()
    out = {}
    for m in re.finditer(r'<DataArray type="Float64" Name="(\w+)"[^>]*NumberOfComponents="(\d+)"[^>]*>\s*([A-Za-z0-9+/=]+)\s*</DataArray>', text):
        name, comps, data = m.group(1), int(m.group(2)), m.group(3)
        raw = base64.b64decode(data)
        n = struct.unpack("<Q", raw[:8])[0] // 8
        vals = struct.unpack(f"<{n}d", raw[8:8 + 8 * n])
        out[name] = [vals[i:i + comps] for i in range(0, n, comps)]
    for m in re.finditer(r'<Points>\s*<DataArray type="Float64"[^>]*NumberOfComponents="(\d+)"[^>]*>\s*([A-Za-z0-9+/=]+)\s*</DataArray>', text):
        comps, data = int(m.group(1)), m.group(2)
        raw = base64.b64decode(data)
        n = struct.unpack("<Q", raw[:8])[0] // 8
        vals = struct.unpack(f"<{n}d", raw[8:8 + 8 * n])
        out["points"] = [vals[i:i + comps] for i in range(0, n, comps)]
    return out


def boundary_angle(x, cls, y0, band):
    """Band boundaries between cls True (left) and False, line fit, angle (deg)."""
    top = max(p[1] for p in x)
    nb = math.ceil((top - y0) / band)
    rows = [[] for _ in range(nb)]
    for p, c in zip(x, cls):
        if p[1] >= y0:
            rows[min(int((p[1] - y0) / band), nb - 1)].append((p[0], c))
    pts = []
    for k, row in enumerate(rows):
        m = sum(1 for r in row if r[1])
        if m < 2 or len(row) - m < 2:
            continue
        row.sort()
        cost = m
        best, at = cost, 0
        for c, r in enumerate(row):
            cost += -1 if r[1] else 1
            if cost < best:
                best, at = cost, c + 1
        if at == 0:
            xb = row[0][0]
        elif at == len(row):
            xb = row[-1][0]
        else:
            xb = 0.5 * (row[at - 1][0] + row[at][0])
        pts.append((xb, y0 + (k + 0.5) * band))
    if len(pts) < 2:
        return None
    n = len(pts)
    my = sum(p[1] for p in pts) / n
    mx = sum(p[0] for p in pts) / n
    sxy = sum((p[1] - my) * (p[0] - mx) for p in pts)
    syy = sum((p[1] - my) ** 2 for p in pts)
    return math.degrees(math.atan2(1.0, sxy / syy))


def measure(run):
    scene = tomllib.load(open(run.rstrip("/") + ".toml", "rb"))
    fault = scene["nscd"]["fault"]
    summary = json.load(open(f"{run}/summary.json"))
    frames = sorted(glob.glob(f"{run}/vtk/particles_*.vtp"))
    a = arrays(frames[-1])
    t = scene["schedule"]["end_time"]
    s = fault["slip_rate"] * t
    dip = math.radians(fault["dip"])
    tip = [fault["tip"][0] + s * math.cos(dip), fault["tip"][1] + s * math.sin(dip)]
    (x0, y0), (x1, y1) = fault["window"]
    r_max = max(scene["particles"]["radius"])
    band = fault.get("band", 4.0 * r_max)
    x, u = [], []
    for p, d in zip(a["points"], a["displacement"]):
        if x0 <= p[0] <= x1 and y0 <= p[1] <= y1:
            x.append(p[:2])
            u.append(math.hypot(d[0], d[1]))
    half = boundary_angle(x, [v >= 0.5 * s for v in u], tip[1], band)
    left = boundary_angle(x, [v >= (1 - F) * s for v in u], tip[1], band)
    right = boundary_angle(x, [v >= F * s for v in u], tip[1], band)
    f = summary.get("fault") or {}
    tri = f.get("trishear") or {}
    fmt = lambda v: "—" if v is None else f"{v:.1f}"
    apex = None if left is None or right is None else left - right
    return (f"| {run.rstrip('/').split('/')[-1]} | {fmt(f.get('limit_angle_deg'))} | {fmt(half)} | "
            f"{fmt(left)} | {fmt(right)} | {fmt(apex)} | {fmt(f.get('run_out'))} | "
            f"{fmt(tri.get('half_apex_deg'))} | {tri.get('l2', float('nan')):.3f} |")


print("| run | θ_l summary | half (°) | left (°) | right (°) | apex (°) | run-out (m) | φ_a (°) | trishear L2 |")
print("|---|---|---|---|---|---|---|---|---|")
for run in sys.argv[1:]:
    print(measure(run))
