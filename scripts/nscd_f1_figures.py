#!/usr/bin/env python3
"""The forced-fold experiment F1 (Renouf, Dubois & Alart (2006) §5.2) from a run's output:
its four acceptance gates and the figures of the paper's Figs. 6-10.

    python3 scripts/nscd_f1_figures.py OUT_DIR [--scale S] [--figures DIR] [--prefix NAME]
                                       [--stages N] [--every K] [--until T]

OUT_DIR is the output directory of `porofrac run scenes/nscd/forced_fold_paper.toml`
(scale 1, the default) or of `scenes/nscd/forced_fold_wedge.toml` (`--scale 0.2`): the
particle and contact frames `vtk/particles_*.vtp`, `vtk/contacts_*.vtp` (binary base64,
UInt64 headers) listed with their times in `*.pvd`, `probes.csv` with p, q,
dilation_x and dilation_y of the tracked cells W1-W6, and `summary.json` once the run
has ended (its status, steps, sweeps and contacts are printed). A run still going (or stopped and
resumed) can be read at any time: the frames written so far are used (or those up to
--until T seconds), and the gates are stated for the time reached. Nothing in OUT_DIR is
written.

The geometry is the paper's scaled by S: a layer of thickness h = 30 S m on the base,
the left wall moving at 0.5 m/s (the speed is not scaled), the tracked cells W1-W6 at
the paper's centres and radii times S.

Gates (SEEDS 003.5 item 7), each printed with its numbers and a verdict:

1. **Non-linear wedge front** (Fig. 7): the free surface is the highest disk top in bins
   of one mean diameter; the front is the first bin right of the moving wall whose surface
   is below the layer top plus one mean diameter. The straight line fitted to front
   against wall displacement leaves residuals; the curve is called non-linear when the
   largest residual exceeds three mean diameters (the grain-size noise of the front is
   about one). Needs at least four frames.
2. **W2 lambda_x in [1.6, 2.4]** at the end of the run (500 S s: 25 % shortening of the
   layer of length 1000 S m); before the end the value reached is printed and the
   verdict is "pending".
3. **W3 and W4 peaks of p above W1's** (the largest p of each cell over the run).
4. **W6 flat**: every p of W6 within 10 % of its mean over the run.

Figures (PNG, into --figures, default docs/nscd, names starting with --prefix, default
f1_paper or f1_wedge by scale):

* `_layers.png` (Fig. 6): the disks at N stages (default 4, the first and last frames and
  evenly between), coloured by the nine layers of equal thickness of their initial height
  in the layer (the wedge above it in grey), with the tracked cells' initial circles;
* `_front.png` (Fig. 7): wedge-front position against wall displacement, with the
  straight-line fit;
* `_stress.png` (Figs. 8-9): p and q (kPa) in W1-W6 against shortening (m);
* `_fabric.png` (Fig. 10): dilatations lambda_x, lambda_y of W1-W6 (probes) and the
  fabric anisotropy a = (f1 - f2)/2 of the contacts between tracked particles, f =
  sum n n^T / N over the contacts that carry a force (normalised by their number), from
  the contact frames (every K-th frame, default every frame).
"""
import argparse
import base64
import csv
import glob
import os
import re
import sys

import numpy as np

# The paper's tracked cells (centre x, centre y, radius), m.
CELLS = [(100.0, 45.0, 20.0), (200.0, 25.0, 20.0), (300.0, 15.0, 12.0),
         (400.0, 15.0, 12.0), (500.0, 15.0, 12.0), (600.0, 15.0, 12.0)]
LAYER = 30.0  # the paper's layer thickness h (m)
SPEED = 0.5  # left wall speed (m/s)
END = 500.0  # the paper's end time (s): 25 % of its 1000 m layer at 0.5 m/s


def vtk_array(text, name, width):
    """A binary base64 DataArray of Float64 (or Int/UInt 64) values, as numpy."""
    m = re.search(r'<DataArray type="(\w+)" Name="%s"[^>]*>\s*([A-Za-z0-9+/=]+)\s*<' % name, text)
    if m is None:
        raise SystemExit(f"no array {name!r} in a frame")
    raw = base64.b64decode(m.group(2))
    size = int(np.frombuffer(raw[:8], dtype="<u8")[0])
    kind = {"Float64": "<f8", "Int64": "<i8", "UInt64": "<u8", "Float32": "<f4",
            "Int32": "<i4", "UInt32": "<u4", "UInt8": "u1"}[m.group(1)]
    data = np.frombuffer(raw[8:8 + size], dtype=kind)
    return data.reshape(-1, width) if width > 1 else data


def frames(out):
    """(time, particles file, contacts file or None) of every frame, in time order."""
    rows = []
    for pvd in glob.glob(os.path.join(out, "*.pvd")):
        if pvd.endswith("_contacts.pvd"):
            continue
        for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', open(pvd).read()):
            if "particles_" in f:
                p = os.path.join(out, f)
                c = p.replace("particles_", "contacts_")
                if os.path.exists(p):
                    rows.append((float(t), p, c if os.path.exists(c) else None))
    rows.sort()
    if not rows:
        raise SystemExit(f"no particle frames listed in a .pvd file of {out}")
    return rows


def particles(path):
    text = open(path).read()
    x = vtk_array(text, "Points", 3)[:, :2]
    r = vtk_array(text, "radius", 1)
    u = vtk_array(text, "displacement", 3)[:, :2]
    return x, r, u


def contacts(path):
    """Contact lines (two end points each) and their normal forces."""
    text = open(path).read()
    pts = vtk_array(text, "Points", 3)[:, :2]
    fn = vtk_array(text, "normal_force", 1)
    return pts[0::2], pts[1::2], fn


def front(x, r, wall, top, bin_width):
    """The wedge front: first bin right of the wall whose surface is below top + bin."""
    b = np.floor(x[:, 0] / bin_width).astype(int)
    surface = {}
    for k, y in zip(b, x[:, 1] + r):
        if y > surface.get(k, -np.inf):
            surface[k] = y
    k = int(np.floor(wall / bin_width)) + 1
    while k in surface and surface[k] > top + bin_width:
        k += 1
    return k * bin_width


def read_probes(out):
    path = os.path.join(out, "probes.csv")
    with open(path) as f:
        rows = list(csv.reader(f))
    head = [h.split(" [")[0] for h in rows[0]]
    data = np.array([[float(v) for v in row] for row in rows[1:] if row], dtype=float)
    return {h: data[:, k] for k, h in enumerate(head)}


def verdict(ok, done=True, t=None):
    word = "holds" if ok else "does not hold"
    return word if done else f"{word} so far (t = {t:g} s, pending)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--figures", default="docs/nscd")
    ap.add_argument("--prefix", default=None)
    ap.add_argument("--stages", type=int, default=4)
    ap.add_argument("--every", type=int, default=1)
    ap.add_argument("--until", type=float, default=None)
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import EllipseCollection

    s = a.scale
    prefix = a.prefix or ("f1_paper" if s == 1.0 else "f1_wedge")
    cells = [(cx * s, cy * s, rc * s) for cx, cy, rc in CELLS]
    top = LAYER * s
    rows = frames(a.out)
    probes = read_probes(a.out)
    if a.until is not None:
        rows = [r for r in rows if r[0] <= a.until]
        keep = probes["time"] <= a.until
        probes = {k: v[keep] for k, v in probes.items()}
    t_end = probes["time"][-1]
    wall_of = lambda t: SPEED * t
    os.makedirs(a.figures, exist_ok=True)

    # Initial state: tracked sets and layers.
    x0, r0, u0 = particles(rows[0][1])
    init = x0 - u0
    diameter = 2.0 * float(np.mean(r0))
    tracked = [np.hypot(init[:, 0] - cx, init[:, 1] - cy) <= rc for cx, cy, rc in cells]

    done = t_end >= END * s * (1.0 - 1e-9)
    summary = os.path.join(a.out, "summary.json")
    if os.path.exists(summary):
        import json

        sm = json.load(open(summary))
        sw, ct = sm.get("sweeps") or {}, sm.get("contacts") or {}
        print(f"summary.json: status {sm.get('status')!r}, {sm.get('steps')} steps, "
              f"{sm.get('particles')} disks, sweeps per step mean {sw.get('mean')} max "
              f"{sw.get('max')}, contacts mean {ct.get('mean')} max {ct.get('max')}, "
              f"not converged steps {sm.get('not_converged_steps')}, wall "
              f"{(sm.get('wall_seconds') or {}).get('total')} s")
    else:
        print("no summary.json yet: the run is going or was stopped")

    # Gate 1: the wedge front over the frames.
    fronts = []
    for t, p, _ in rows:
        x, r, _ = particles(p)
        fronts.append((wall_of(t), front(x, r, wall_of(t), top, diameter)))
    fr = np.array(fronts)
    print(f"{len(rows)} frames, t = {rows[0][0]:g} .. {rows[-1][0]:g} s; probes to t = {t_end:g} s "
          f"(end of the experiment: {END * s:g} s); {len(r0)} disks, mean diameter {diameter:.3f} m")
    print("wall (m)  front (m)")
    for w, f in fr:
        print(f"{w:8.2f}  {f:8.2f}")
    if len(fr) >= 4:
        slope, icpt = np.polyfit(fr[:, 0], fr[:, 1], 1)
        res = fr[:, 1] - (slope * fr[:, 0] + icpt)
        worst = float(np.max(np.abs(res)))
        ok = worst > 3.0 * diameter
        print(f"gate 1, non-linear wedge front: straight line slope {slope:.3f}, max |residual| "
              f"{worst:.2f} m = {worst / diameter:.1f} diameters (> 3 for non-linear), rms "
              f"{float(np.sqrt(np.mean(res ** 2))):.2f} m: {verdict(ok, done, rows[-1][0])}")
    else:
        slope = icpt = None
        print(f"gate 1, non-linear wedge front: {len(fr)} frames, at least 4 needed: pending")

    # Gate 2: W2 lambda_x at the end.
    lx2 = probes["dilation_x_W2"][-1]
    inside = 1.6 <= lx2 <= 2.4
    state = verdict(inside) if done else ("pending" + (", inside now" if inside else ""))
    print(f"gate 2, W2 lambda_x in [1.6, 2.4] at the end: {lx2:.3f} at t = {t_end:g} s "
          f"(lambda_y {probes['dilation_y_W2'][-1]:.3f}): {state}")

    # Gate 3: W3, W4 peaks of p above W1's.
    peak = {k: float(np.max(probes[f"p_W{k}"])) for k in range(1, 7)}
    when = {k: float(probes["time"][np.argmax(probes[f"p_W{k}"])]) for k in range(1, 7)}
    ok3 = peak[3] > peak[1] and peak[4] > peak[1]
    print(f"gate 3, W3/W4 peak p above W1's: W1 {peak[1] / 1e3:.1f} kPa (t = {when[1]:g} s), "
          f"W3 {peak[3] / 1e3:.1f} kPa (t = {when[3]:g} s), W4 {peak[4] / 1e3:.1f} kPa "
          f"(t = {when[4]:g} s): {verdict(ok3, done, t_end)}")

    # Gate 4: W6 flat within 10 % of its mean.
    p6 = probes["p_W6"]
    mean6 = float(np.mean(p6))
    dev = float(np.max(np.abs(p6 - mean6)) / abs(mean6))
    print(f"gate 4, W6 flat: p mean {mean6 / 1e3:.1f} kPa, range {np.min(p6) / 1e3:.1f} .. "
          f"{np.max(p6) / 1e3:.1f} kPa, largest deviation {100 * dev:.1f} % of the mean "
          f"(<= 10 %): {verdict(dev <= 0.10, done, t_end)}")

    # Fig. 6: layers at stages.
    n = min(a.stages, len(rows))
    pick = sorted(set(int(round(k)) for k in np.linspace(0, len(rows) - 1, n)))
    lo, hi = float(np.min(init[:, 1] - r0)), top
    band = np.clip(((init[:, 1] - lo) / (hi - lo) * 9).astype(int), 0, 9)
    # Nine layers in the colours of tab10 but its grey, the wedge above them in grey.
    colours = plt.get_cmap("tab10")(np.array([0, 1, 2, 3, 4, 5, 6, 8, 9, 7]))
    colours[9] = (0.75, 0.75, 0.75, 1.0)
    xmax = float(np.max(init[:, 0] + r0))
    fig, axes = plt.subplots(len(pick), 1, figsize=(16, 0.6 + 2.0 * len(pick)), squeeze=False)
    for ax, k in zip(axes[:, 0], pick):
        t, p, _ = rows[k]
        x, r, _ = particles(p)
        ec = EllipseCollection(2 * r, 2 * r, np.zeros_like(r), units="xy", offsets=x,
                               offset_transform=ax.transData, facecolors=colours[band],
                               edgecolors="none", antialiased=False)
        ax.add_collection(ec)
        for (cx, cy, rc), name in zip(cells, [f"W{j}" for j in range(1, 7)]):
            ax.add_patch(plt.Circle((cx, cy), rc, fill=False, lw=0.8, color="k"))
            ax.text(cx, cy + rc, name, ha="center", va="bottom", fontsize=7)
        ax.set_xlim(-0.02 * xmax, 1.02 * xmax)
        ax.set_ylim(0, float(np.max(x[:, 1] + r)) * 1.1)
        ax.set_aspect("equal")
        ax.set_ylabel("y (m)")
        ax.set_title(f"t = {t:g} s, shortening {wall_of(t):g} m", fontsize=9)
    axes[-1, 0].set_xlabel("x (m)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_layers.png"), dpi=100)
    plt.close(fig)

    # Fig. 7: the wedge front.
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(fr[:, 0], fr[:, 1], "o-", ms=3, label="wedge front")
    if slope is not None:
        ax.plot(fr[:, 0], slope * fr[:, 0] + icpt, "--", label=f"straight line, slope {slope:.2f}")
    ax.set_xlabel("wall displacement (m)")
    ax.set_ylabel("wedge-front position x (m)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_front.png"), dpi=110)
    plt.close(fig)

    # Figs. 8-9: p and q against shortening.
    short = wall_of(probes["time"])
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    for ax, field, label in [(axes[0], "p", "p (kPa)"), (axes[1], "q", "q (kPa)")]:
        for k in range(1, 7):
            ax.plot(short, probes[f"{field}_W{k}"] / 1e3, label=f"W{k}")
        ax.set_xlabel("shortening (m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_stress.png"), dpi=110)
    plt.close(fig)

    # Fig. 10: dilatations and fabric anisotropy.
    aniso = []
    for k, (t, p, c) in enumerate(rows):
        if c is None or k % a.every:
            continue
        x, _, u = particles(p)
        ends_a, ends_b, fn = contacts(c)
        key = lambda q: np.round(q * 1e6).astype(np.int64)
        index = {tuple(q): i for i, q in enumerate(key(x))}
        ia = np.array([index.get(tuple(q), -1) for q in key(ends_a)])
        ib = np.array([index.get(tuple(q), -1) for q in key(ends_b)])
        row = [wall_of(t)]
        for tr in tracked:
            sel = (ia >= 0) & (ib >= 0) & (fn != 0.0)
            sel[sel] &= tr[ia[sel]] & tr[ib[sel]]
            d = ends_b[sel] - ends_a[sel]
            d /= np.linalg.norm(d, axis=1)[:, None]
            if len(d) == 0:
                row.append(np.nan)
                continue
            f = d.T @ d / len(d)
            ev = np.linalg.eigvalsh(f)
            row.append(0.5 * (ev[1] - ev[0]))
        aniso.append(row)
    aniso = np.array(aniso)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4))
    for k in range(1, 7):
        axes[0].plot(short, probes[f"dilation_x_W{k}"], label=f"W{k}")
        axes[1].plot(short, probes[f"dilation_y_W{k}"], label=f"W{k}")
        if len(aniso):
            axes[2].plot(aniso[:, 0], aniso[:, k], "o-", ms=3, label=f"W{k}")
    axes[0].axhspan(1.6, 2.4, color="0.9", zorder=0)
    for ax, label in zip(axes, ["dilatation lambda_x (-)", "dilatation lambda_y (-)",
                                "fabric anisotropy a = (f1 - f2)/2 (-)"]):
        ax.set_xlabel("shortening (m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_fabric.png"), dpi=110)
    plt.close(fig)
    print(f"figures: {a.figures}/{prefix}_{{layers,front,stress,fabric}}.png")


if __name__ == "__main__":
    sys.exit(main())
