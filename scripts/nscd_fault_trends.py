#!/usr/bin/env python3
"""The fault measures of F2 (Renouf et al. (2006) §5.3) per cohesion γ over several
packings, from `porofrac run` outputs of model nscd with `[nscd.fault]`, with their
mean and standard deviation: the table of docs/nscd/fault_trends.md.

    python3 scripts/nscd_fault_trends.py RUN_DIR [RUN_DIR ...]

Each RUN_DIR needs the scene copy next to it (RUN_DIR.toml, as
scripts/nscd_fault_variants.sh leaves it: γ and the packing seed are read from it), its
summary.json and its particle frames vtk/particles_NNNN.vtp (the last one at the end of
the run, one `velocity_window` earlier for the velocities). Reads the VTK frames with the
standard library and numpy only.

Per run, recomputed here from the frames (independently of the Rust code, and checked
against summary.json where the run wrote the same key):

* band θ_l — `fault.limit_angle_deg`: least-squares line through band boundaries of the
  half-slip contour, bands of 4 r_max from the tip height to the top of the sample
  (taken from summary.json);
* axis, left, right, opening — `fault.area`: rays from the current tip that best
  separate the particles moved by ≥ s/2, ≥ (1 − f)s, ≥ f s (f = limit_fraction, default
  0.2) from the others, over the window's particles between the tip height and the
  initial free surface; opening = left − right (the paper's θ_l, the one angle the left
  and right limits reduce to);
* run-out — `fault.run_out` (taken from summary.json);
* L2 window — `fault.trishear.l2` (from summary.json) and L2 layer — the same fit over the
  window's particles at or below the initial free surface (`fault.trishear.layer`).
"""
import base64
import glob
import math
import re
import statistics as st
import struct
import sys
import json
import tomllib

import numpy as np


def arrays(path):
    text = open(path).read()
    out = {}
    for m in re.finditer(r"<DataArray ([^>]*)>\s*([A-Za-z0-9+/=]+)\s*</DataArray>", text):
        attr, data = m.group(1), m.group(2)
        typ = re.search(r'type="(\w+)"', attr).group(1)
        name = re.search(r'Name="(\w+)"', attr).group(1)
        c = re.search(r'NumberOfComponents="(\d+)"', attr)
        raw = base64.b64decode(data)
        n = struct.unpack("<Q", raw[:8])[0] // 8
        a = np.frombuffer(raw[8:8 + 8 * n], dtype="<f8" if typ == "Float64" else "<i8")
        out[name] = a.reshape(-1, int(c.group(1))) if c else a
    return out


def ray_angle(x, moved, tip):
    """The ray of crates/scene/src/nscd/fault.rs `ray_angle` (grid 1°..179° by 0.5°)."""
    if moved.all() or not moved.any():
        return None
    polar = np.degrees(np.arctan2(x[:, 1] - tip[1], x[:, 0] - tip[0]))
    grid = 0.5 * np.arange(2, 359)
    cost = np.array([(moved & (polar < a)).sum() + (~moved & (polar >= a)).sum() for a in grid])
    first = int(np.argmax(cost == cost.min()))
    last = first
    while last + 1 < len(grid) and cost[last + 1] == cost[first]:
        last += 1
    return 0.5 * (grid[first] + grid[last])


def trishear(p, tip, dip, phi, v0):
    e = np.array([math.cos(dip), math.sin(dip)])
    n = np.array([-e[1], e[0]])
    d = p - tip
    X, Y, t = d @ e, d @ n, math.tan(phi)
    vx, vy = np.zeros(len(p)), np.zeros(len(p))
    z2 = (X > 0) & (np.abs(Y) <= X * t)
    s = Y[z2] / (X[z2] * t)
    vx[z2] = 0.5 * v0 * (s + 1)
    vy[z2] = 0.25 * v0 * t * (s * s - 1)
    vx[((X > 0) & (Y > X * t)) | ((X <= 0) & (Y > 0))] = v0
    return np.outer(vx, e) + np.outer(vy, n)


def fit(x, v, tip, dip, v0):
    best = (None, math.inf)
    for d in range(1, 90):
        a = trishear(x, tip, dip, math.radians(d), v0)
        m = math.sqrt(((v - a) ** 2).sum() / (a ** 2).sum())
        if m < best[1]:
            best = (d, m)
    return best


def measure(run):
    run = run.rstrip("/")
    scene = tomllib.load(open(run + ".toml", "rb"))
    summary = json.load(open(f"{run}/summary.json"))
    f = scene["nscd"]["fault"]
    frac = f.get("limit_fraction", 0.2)
    t_end = scene["schedule"]["end_time"]
    vw = f.get("velocity_window", 1.0)
    frames = sorted(glob.glob(f"{run}/vtk/particles_*.vtp"))
    every = scene["output"]["every"] * scene["schedule"]["dt"]
    back = round(vw / every)
    a, b = arrays(frames[-1]), arrays(frames[-1 - back])
    assert (a["id"] == b["id"]).all()
    x, u = a["Points"][:, :2], a["displacement"][:, :2]
    v = (x - b["Points"][:, :2]) / vw
    y_top = ((x - u)[:, 1] + a["radius"]).max()
    v0, dip = f["slip_rate"], math.radians(f["dip"])
    s = v0 * t_end
    e = np.array([math.cos(dip), math.sin(dip)])
    tip = np.array(f["tip"]) + s * e
    tip_mid = np.array(f["tip"]) + v0 * (t_end - 0.5 * vw) * e
    (wx0, wy0), (wx1, wy1) = f["window"]
    w = (x[:, 0] >= wx0) & (x[:, 0] <= wx1) & (x[:, 1] >= wy0) & (x[:, 1] <= wy1)
    xw, uw, vw_ = x[w], u[w], v[w]
    um = np.hypot(uw[:, 0], uw[:, 1])
    lay = (xw[:, 1] > tip[1]) & (xw[:, 1] <= y_top)
    ray = lambda k: ray_angle(xw[lay], um[lay] >= k * s, tip)
    left, axis, right = ray(1 - frac), ray(0.5), ray(frac)
    below = xw[:, 1] <= y_top
    phi_l, l2_l = fit(xw[below], vw_[below], tip_mid, dip, v0)
    fs = summary.get("fault") or {}
    tri = fs.get("trishear") or {}
    area = fs.get("area")
    if area is not None:
        for k, mine in (("axis_deg", axis), ("left_deg", left), ("right_deg", right)):
            assert area[k] is not None and abs(area[k] - mine) < 1e-9, (run, k, area[k], mine)
    return {
        "gamma": scene["contact"].get("cohesion", 0.0),
        "seed": scene["particles"].get("seed", 1),
        "band": fs.get("limit_angle_deg"),
        "axis": axis,
        "left": left,
        "right": right,
        "opening": None if left is None or right is None else left - right,
        "run_out": fs.get("run_out"),
        "phi_a": tri.get("half_apex_deg"),
        "l2": tri.get("l2"),
        "phi_layer": phi_l,
        "l2_layer": l2_l,
    }


COLS = ["band", "axis", "left", "right", "opening", "run_out", "phi_a", "l2", "phi_layer", "l2_layer"]
HEAD = ["θ_l band (°)", "axis (°)", "left (°)", "right (°)", "opening θ_l (°)", "run-out (m)",
        "φ_a (°)", "L2 window", "φ_a layer (°)", "L2 layer"]


def fmt(k, v):
    if v is None:
        return "—"
    return f"{v:.3f}" if k.startswith("l2") else (f"{v:.2f}" if k == "run_out" else f"{v:.1f}")


rows = [measure(r) for r in sys.argv[1:]]
rows.sort(key=lambda r: (r["gamma"], r["seed"]))
print("| γ (N/m) | seed | " + " | ".join(HEAD) + " |")
print("|---|---|" + "---|" * len(COLS))
for r in rows:
    print(f"| {r['gamma']:g} | {r['seed']} | " + " | ".join(fmt(k, r[k]) for k in COLS) + " |")
print()
print("| γ (N/m) | packings | " + " | ".join(HEAD) + " |")
print("|---|---|" + "---|" * len(COLS))
gammas = sorted({r["gamma"] for r in rows})
for g in gammas:
    rs = [r for r in rows if r["gamma"] == g]
    cells = []
    for k in COLS:
        xs = [r[k] for r in rs if r[k] is not None]
        sd = st.stdev(xs) if len(xs) > 1 else 0.0
        cells.append(f"{fmt(k, st.mean(xs))} ± {fmt(k, sd)}" if xs else "—")
    print(f"| {g:g} | {len(rs)} | " + " | ".join(cells) + " |")
print()
# Per packing: how many packings order the ends of the γ range as the paper does.
if len(gammas) >= 2:
    lo, hi = gammas[0], gammas[-1]
    by = {(r["gamma"], r["seed"]): r for r in rows}
    seeds = sorted({r["seed"] for r in rows if (lo, r["seed"]) in by and (hi, r["seed"]) in by})
    for k, sign, what in (("opening", -1, "opening falls"), ("axis", -1, "axis falls"),
                          ("run_out", -1, "run-out falls"), ("l2_layer", 1, "L2 layer rises"),
                          ("l2", 1, "L2 window rises")):
        n = sum(1 for sd in seeds if sign * (by[(hi, sd)][k] - by[(lo, sd)][k]) > 0)
        mono = sum(1 for sd in seeds if all(
            (g1, sd) in by and (g2, sd) in by and sign * (by[(g2, sd)][k] - by[(g1, sd)][k]) > 0
            for g1, g2 in zip(gammas, gammas[1:])))
        print(f"- {what} from γ = {lo:g} to {hi:g}: {n} of {len(seeds)} packings; "
              f"monotonic over all γ: {mono} of {len(seeds)}")
    below = sum(1 for sd in seeds if by[(hi, sd)]["opening"] < 30.0)
    above = sum(1 for sd in seeds if by[(lo, sd)]["opening"] > 30.0)
    print(f"- opening above 30° at γ = {lo:g}: {above} of {len(seeds)}; "
          f"below 30° at γ = {hi:g}: {below} of {len(seeds)}")
