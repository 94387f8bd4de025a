#!/usr/bin/env python3
"""The forced-fold experiment F1 (Renouf, Dubois & Alart (2006) §5.2) from a run's output:
its four acceptance gates and the figures of the paper's Figs. 6-10.

    python3 scripts/nscd_f1_figures.py OUT_DIR [--scale S] [--figures DIR] [--prefix NAME]
                                       [--stages N] [--every K] [--until T] [--lift H]
                                       [--speed V]

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
the paper's centres and radii times S. --lift H raises the layer's top and the cells by
H m (the rough-base variants of scripts/nscd_f1_rough_base.py --height H); --speed V
reads a run whose left wall moves at V m/s instead (the end of the experiment is then
the time the wall has travelled the paper's 250 S m).

The tracked cells are the paper's: the set Omega of the particles whose centres lie in
the circle (cx, cy, R) at t = 0 (the settled sample), followed through the run; the
solver's probes of `probes.csv` are the same sets (fixed when the run starts), measured
every step, and the script measures them again on the frames (checked to agree).
Eq. 7, sigma = (1/vol Omega) sum r_a (x) l_a, is read four ways, each printed:

* the contacts counted: those between two tracked particles with l = (r_i + r_j) n (the
  probes' reading), or every contact of a tracked particle (with a particle outside the
  set or a wall too), each tracked particle adding its half r_i n (Love's formula for a
  set of particles);
* vol Omega: the disks' area over the cell's initial packing fraction (for rigid disks
  the initial circle's area pi R^2 at every time: the probes' reading), or the convex hull
  of the centres grown by the mean radius (Steiner: A + P r + pi r^2).

lambda_x, lambda_y (eq. 11) are the extents of the tracked centres over their extents
at t = 0; the fabric anisotropy (eqs. 9-10) is over the force-carrying contacts between
tracked particles, normalised by their number. `scripts/nscd_f1_figures_check.py` checks
these measures on synthetic frames with known answers.

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
3. **W3 and W4 peaks of p above W1's** (the largest p of each cell over the run): from
   the probes (every step) and, in each of the four readings of eq. 7, from the frames.
4. **W6 flat**: every p of W6 within 10 % of its mean over the run (the same readings).

Figures (PNG, into --figures, default docs/nscd, names starting with --prefix, default
f1_paper or f1_wedge by scale):

* `_layers.png` (Figs. 6 and 8): the disks at N stages (default 4, the first and last
  frames and evenly between), coloured by the nine layers of equal thickness of their
  initial height in the layer (the wedge above it in grey), the tracked particles of
  W1-W6 in black (the cells' shapes of Fig. 8), the left wall as a line;
* `_front.png` (Fig. 7): wedge-front position against wall displacement, with the
  straight-line fit;
* `_stress.png` (Figs. 8-9): p and q (kPa) in W1-W6 against shortening (m), from the
  probes (lines) and over every contact of the tracked particles (frames, dots);
* `_fabric.png` (Fig. 10): dilatations lambda_x, lambda_y of W1-W6 (probes) and the
  fabric anisotropy a = (f1 - f2)/2 (frames, every K-th frame and the last, default
  every frame).
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
    """Contact lines of a frame: the antagonist's end (a disk's centre, or the contact
    point on a rigid body), the candidate's centre, and the normal and tangential forces
    on the candidate (N per metre; the tangent is the normal turned +90 degrees)."""
    text = open(path).read()
    pts = vtk_array(text, "Points", 3)[:, :2]
    fn = vtk_array(text, "normal_force", 1)
    ft = vtk_array(text, "tangential_force", 1)
    return pts[0::2], pts[1::2], fn, ft


def contact_index(x, ends_a, ends_b):
    """Particle indices of the contact lines' ends: the antagonist's (-1 for a rigid
    body, whose end is the contact point) and the candidate's (the second end is always a
    centre). A frame writes the centres and the line ends as the same float64 values, so
    they match exactly."""
    index = {(float(p[0]), float(p[1])): i for i, p in enumerate(x)}
    ia = np.array([index.get((float(p[0]), float(p[1])), -1) for p in ends_a], dtype=np.int64)
    ib = np.array([index.get((float(p[0]), float(p[1])), -1) for p in ends_b], dtype=np.int64)
    if np.any(ib < 0):
        raise SystemExit(f"{int(np.sum(ib < 0))} contact lines end off every particle centre")
    return ia, ib


def hull(points):
    """Area and perimeter of the convex hull of 2-D points (Andrew's monotone chain)."""
    pts = sorted(set((float(p[0]), float(p[1])) for p in points))
    if len(pts) < 3:
        return 0.0, 0.0

    def chain(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0.0:
                out.pop()
            out.append(p)
        return out

    ring = np.array(chain(pts)[:-1] + chain(pts[::-1])[:-1])
    nxt = np.roll(ring, -1, axis=0)
    area = 0.5 * abs(float(np.sum(ring[:, 0] * nxt[:, 1] - ring[:, 1] * nxt[:, 0])))
    return area, float(np.sum(np.hypot(*(nxt - ring).T)))


class Cell:
    """A tracked cell of the paper: the set Omega of the particles whose centres lie in the
    circle (cx, cy, R) in the first frame (the settled state at t = 0), followed by their
    indices through the run (Renouf et al. 2006 section 5.2.3: "the stress tensor of a cell
    is computed from particles initially located in the corresponding cell")."""

    def __init__(self, x0, r, centre, radius):
        self.member = np.hypot(x0[:, 0] - centre[0], x0[:, 1] - centre[1]) <= radius
        if not np.any(self.member):
            raise SystemExit(f"the cell {centre}, R = {radius} holds no particle")
        self.extent0 = np.ptp(x0[self.member], axis=0)
        self.area = float(np.sum(np.pi * r[self.member] ** 2))
        # The initial packing fraction of the cell: its disks' area over the circle's.
        self.phi0 = self.area / (np.pi * radius ** 2)

    def volume(self, x, r, kind):
        """vol Omega of eq. 7: "areas" = the disks' area over the initial packing fraction
        (for rigid disks the circle's area pi R^2 at every time), or "hull" = the convex
        hull of the centres grown by the mean radius (Steiner: A + P r + pi r^2)."""
        if kind == "areas":
            return self.area / self.phi0
        rbar = float(np.mean(r[self.member]))
        a, per = hull(x[self.member])
        return a + per * rbar + np.pi * rbar ** 2

    def measure(self, x, r, lines, counted="internal", volume="areas"):
        """Stress (eq. 7, compression positive), p and q (eq. 8), fabric anisotropy
        (eqs. 9-10, normalised by the number of force-carrying contacts) and dilatations
        (eq. 11) of the cell at centres x with the contact lines
        (ends_a, ends_b, fn, ft, ia, ib) of the same frame.

        counted = "internal": the contacts between two particles of Omega, branch vector
        l = (r_i + r_j) n (the solver's probes); "touching": every contact of a particle
        of Omega (with a particle outside it or a wall too), each particle of Omega adding
        its own half of the branch, r_i n (Love's formula for the set: internal contacts
        give the same (r_i + r_j) n)."""
        ends_a, ends_b, fn, ft, ia, ib = lines
        m = self.member
        d = ends_b - ends_a
        n = d / np.linalg.norm(d, axis=1)[:, None]
        t = np.stack([-n[:, 1], n[:, 0]], axis=1)
        f = fn[:, None] * n + ft[:, None] * t
        ma = np.zeros(len(ia), dtype=bool)
        ma[ia >= 0] = m[ia[ia >= 0]]
        mb = m[ib]
        ra = np.where(ia >= 0, r[np.maximum(ia, 0)], 0.0)
        if counted == "internal":
            sel = ma & mb
            arm = np.where(sel, ra + r[ib], 0.0)
        elif counted == "touching":
            sel = ma | mb
            arm = np.where(ma, ra, 0.0) + np.where(mb, r[ib], 0.0)
        else:
            raise ValueError(counted)
        vol = self.volume(x, r, volume)
        sigma = (f[sel].T * arm[sel]) @ n[sel] / vol
        sym = 0.5 * (sigma + sigma.T)
        centre = 0.5 * (sym[0, 0] + sym[1, 1])
        radius = float(np.hypot(0.5 * (sym[0, 0] - sym[1, 1]), sym[0, 1]))
        carry = sel & (fn != 0.0)
        if np.any(carry):
            fab = n[carry].T @ n[carry] / int(np.sum(carry))
            aniso = float(np.hypot(0.5 * (fab[0, 0] - fab[1, 1]), fab[0, 1]))
        else:
            aniso = float("nan")
        ext = np.ptp(x[m], axis=0)
        lam = np.where(self.extent0 > 0, ext / np.where(self.extent0 > 0, self.extent0, 1), 1.0)
        return {"sigma": sigma, "p": centre, "q": radius, "anisotropy": aniso,
                "lx": float(lam[0]), "ly": float(lam[1]), "contacts": int(np.sum(sel)),
                "volume": vol}


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
    ap.add_argument("--lift", type=float, default=0.0)
    ap.add_argument("--speed", type=float, default=SPEED)
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import EllipseCollection

    s = a.scale
    prefix = a.prefix or ("f1_paper" if s == 1.0 else "f1_wedge")
    cells = [(cx * s, cy * s + a.lift, rc * s) for cx, cy, rc in CELLS]
    top = LAYER * s + a.lift
    rows = frames(a.out)
    probes = read_probes(a.out)
    if a.until is not None:
        rows = [r for r in rows if r[0] <= a.until]
        keep = probes["time"] <= a.until
        probes = {k: v[keep] for k, v in probes.items()}
    t_end = probes["time"][-1]
    if not a.speed > 0:
        raise SystemExit("--speed must be a positive wall speed (m/s)")
    wall_of = lambda t: a.speed * t
    # The end of the experiment: 25 % of the layer's length travelled by the wall.
    end = END * s * SPEED / a.speed
    os.makedirs(a.figures, exist_ok=True)

    # Initial state (the settled sample at t = 0): the tracked sets and the layers.
    x0, r0, u0 = particles(rows[0][1])
    init = x0 - u0
    diameter = 2.0 * float(np.mean(r0))
    tracked = [Cell(init, r0, (cx, cy), rc) for cx, cy, rc in cells]

    done = t_end >= end * (1.0 - 1e-9)
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
    print("tracked cells (particles whose centres are inside the circle at t = 0): "
          + ", ".join(f"W{k + 1} {int(np.sum(c.member))} disks, packing {c.phi0:.3f}"
                      for k, c in enumerate(tracked)))

    # Every frame: the wedge front; every --every-th frame with contacts: the cells'
    # measures in the four readings of eq. 7 (contacts counted x vol Omega).
    readings = [(c, v) for c in ("internal", "touching") for v in ("areas", "hull")]
    fronts, cellrows = [], []
    for k, (t, p, c) in enumerate(rows):
        x, r, _ = particles(p)
        fronts.append((wall_of(t), front(x, r, wall_of(t), top, diameter)))
        if c is None or (k % a.every and k != len(rows) - 1):
            continue
        ea, eb, fn, ft = contacts(c)
        lines = (ea, eb, fn, ft, *contact_index(x, ea, eb))
        cellrows.append((t, [[cell.measure(x, r, lines, cnt, vol) for cnt, vol in readings]
                             for cell in tracked]))
    fr = np.array(fronts)
    print(f"{len(rows)} frames, t = {rows[0][0]:g} .. {rows[-1][0]:g} s; probes to t = {t_end:g} s "
          f"(end of the experiment: {end:g} s); {len(r0)} disks, mean diameter {diameter:.3f} m")
    print("wall (m)  front (m)")
    for w, f in fr:
        print(f"{w:8.2f}  {f:8.2f}")

    # The probes are the same cells (the solver fixes each set at t = 0 after the
    # settling); check that they and the frames agree where both exist.
    if cellrows:
        t_last, last = cellrows[-1]
        i_last = int(np.argmin(np.abs(probes["time"] - t_last)))
        worst = 0.0
        for k in range(6):
            m = last[k][0]
            for field, v in (("p", m["p"]), ("dilation_x", m["lx"]), ("dilation_y", m["ly"])):
                ref = probes[f"{field}_W{k + 1}"][i_last]
                worst = max(worst, abs(v - ref) / max(abs(ref), 1e-30))
        print(f"probes against the frames' cells at t = {t_last:g} s (contacts between tracked "
              f"particles, vol = disks' area / initial packing): largest relative difference "
              f"{worst:.1e}")
        if worst > 1e-9:
            print("  the script's cells are not the probes' sets: are the centres those of the "
                  "scene (a rough-base variant needs --lift)?")

    # Gate 1: the wedge front.
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

    # Gate 2: W2 lambda_x at the end (eq. 11 has one reading).
    lx2 = probes["dilation_x_W2"][-1]
    inside = 1.6 <= lx2 <= 2.4
    state = verdict(inside) if done else ("pending" + (", inside now" if inside else ""))
    print(f"gate 2, W2 lambda_x in [1.6, 2.4] at the end: {lx2:.3f} at t = {t_end:g} s "
          f"(lambda_y {probes['dilation_y_W2'][-1]:.3f}): {state}")

    # Gates 3 and 4 from the probes (every step) and from the frames in each reading.
    series = [("probes, every step: contacts between tracked particles, vol = disks' area / "
               "initial packing", probes["time"],
               {k: probes[f"p_W{k}"] for k in range(1, 7)})]
    if cellrows:
        times = np.array([t for t, _ in cellrows])
        for j, (cnt, vol) in enumerate(readings):
            name = ("contacts between tracked particles" if cnt == "internal"
                    else "every contact of a tracked particle")
            name += ", vol = " + ("disks' area / initial packing" if vol == "areas"
                                  else "grown convex hull")
            series.append((f"frames ({len(cellrows)}): {name}", times,
                           {k: np.array([row[k - 1][j]["p"] for _, row in cellrows])
                            for k in range(1, 7)}))
    for n, (name, times, p) in enumerate(series):
        peak = {k: float(np.max(p[k])) for k in (1, 3, 4)}
        when = {k: float(times[np.argmax(p[k])]) for k in (1, 3, 4)}
        ok3 = peak[3] > peak[1] and peak[4] > peak[1]
        mean6 = float(np.mean(p[6]))
        dev = float(np.max(np.abs(p[6] - mean6)) / abs(mean6))
        tag = "" if n == 0 else " (other reading)"
        print(f"[{name}]")
        print(f"  gate 3{tag}, W3/W4 peak p above W1's: W1 {peak[1] / 1e3:.1f} kPa "
              f"(t = {when[1]:g} s), W3 {peak[3] / 1e3:.1f} kPa (t = {when[3]:g} s), W4 "
              f"{peak[4] / 1e3:.1f} kPa (t = {when[4]:g} s): {verdict(ok3, done, t_end)}")
        print(f"  gate 4{tag}, W6 flat: p mean {mean6 / 1e3:.1f} kPa, range "
              f"{np.min(p[6]) / 1e3:.1f} .. {np.max(p[6]) / 1e3:.1f} kPa, largest deviation "
              f"{100 * dev:.1f} % of the mean (<= 10 %): {verdict(dev <= 0.10, done, t_end)}")

    # Fig. 6 (and Fig. 8): the layers at stages, the tracked particles in black.
    n = min(a.stages, len(rows))
    pick = sorted(set(int(round(k)) for k in np.linspace(0, len(rows) - 1, n)))
    lo, hi = float(np.min(init[:, 1] - r0)), top
    band = np.clip(((init[:, 1] - lo) / (hi - lo) * 9).astype(int), 0, 9)
    # Nine layers in the colours of tab10 but its grey, the wedge above them in grey.
    colours = plt.get_cmap("tab10")(np.array([0, 1, 2, 3, 4, 5, 6, 8, 9, 7]))
    colours[9] = (0.75, 0.75, 0.75, 1.0)
    face = colours[band].copy()
    for cell in tracked:
        face[cell.member] = (0.0, 0.0, 0.0, 1.0)
    xmax = float(np.max(init[:, 0] + r0))
    stages = [(rows[k][0], *particles(rows[k][1])[:2]) for k in pick]
    ymax = 1.15 * max(float(np.max(x[:, 1] + r)) for _, x, r in stages)
    fig, axes = plt.subplots(len(pick), 1, figsize=(16, 0.9 + 2.0 * len(pick)), squeeze=False)
    for ax, (t, x, r) in zip(axes[:, 0], stages):
        ec = EllipseCollection(2 * r, 2 * r, np.zeros_like(r), units="xy", offsets=x,
                               offset_transform=ax.transData, facecolors=face,
                               edgecolors="none", antialiased=False)
        ax.add_collection(ec)
        for j, cell in enumerate(tracked):
            cx, cy = np.mean(x[cell.member], axis=0)
            ytop = float(np.max(x[cell.member, 1]))
            ax.text(cx, ytop + 2.0 * s, f"W{j + 1}", ha="center", va="bottom", fontsize=8)
        ax.axvline(wall_of(t), color="k", lw=1.5)
        ax.set_xlim(-0.02 * xmax, 1.02 * xmax)
        ax.set_ylim(0, ymax)
        ax.set_aspect("equal")
        ax.set_ylabel("y (m)")
        ax.set_title(f"t = {t:g} s, left wall moved {wall_of(t):g} m (black line); tracked "
                     f"cells W1-W6 in black (the particles inside each circle at t = 0)",
                     fontsize=9)
    axes[-1, 0].set_xlabel("x (m)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_layers.png"), dpi=100)
    plt.close(fig)

    # Fig. 7: the wedge front.
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(fr[:, 0], fr[:, 1], "o-", ms=3, label="wedge front (first bin below layer top + d)")
    if slope is not None:
        ax.plot(fr[:, 0], slope * fr[:, 0] + icpt, "--", label=f"straight line, slope {slope:.2f}")
    ax.set_xlabel("left-wall displacement (m)")
    ax.set_ylabel("wedge-front position x (m)")
    ax.set_title("F1: wedge front against the wall's travel (Fig. 7)", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_front.png"), dpi=110)
    plt.close(fig)

    # Figs. 8-9: p and q against shortening: probes (lines), all contacts of the set
    # (frames, markers).
    short = wall_of(probes["time"])
    colour = plt.get_cmap("tab10")
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    for ax, field, label in [(axes[0], "p", "mean stress p (kPa)"),
                             (axes[1], "q", "deviatoric stress q (kPa)")]:
        for k in range(1, 7):
            ax.plot(short, probes[f"{field}_W{k}"] / 1e3, color=colour(k - 1), lw=0.8,
                    label=f"W{k}")
            if cellrows:
                ax.plot([wall_of(t) for t, _ in cellrows],
                        [row[k - 1][2][field] / 1e3 for _, row in cellrows], "o", ms=2.5,
                        color=colour(k - 1))
        ax.set_xlabel("shortening = left-wall displacement (m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, ncol=2)
    fig.suptitle("F1 tracked cells (Figs. 8-9): lines, contacts between tracked particles "
                 "(every step); dots, every contact of a tracked particle (frames); "
                 "vol = disks' area / initial packing", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_stress.png"), dpi=110)
    plt.close(fig)

    # Fig. 10: dilatations and fabric anisotropy.
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.5))
    for k in range(1, 7):
        axes[0].plot(short, probes[f"dilation_x_W{k}"], color=colour(k - 1), label=f"W{k}")
        axes[1].plot(short, probes[f"dilation_y_W{k}"], color=colour(k - 1), label=f"W{k}")
        if cellrows:
            axes[2].plot([wall_of(t) for t, _ in cellrows],
                         [row[k - 1][0]["anisotropy"] for _, row in cellrows], "o-", ms=3,
                         color=colour(k - 1), label=f"W{k}")
    axes[0].axhspan(1.6, 2.4, color="0.9", zorder=0, label="W2 gate [1.6, 2.4]")
    for ax, label in zip(axes, ["dilatation lambda_x (-)", "dilatation lambda_y (-)",
                                "fabric anisotropy a = (f1 - f2)/2 (-)"]):
        ax.set_xlabel("shortening = left-wall displacement (m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("F1 tracked cells (Fig. 10): extent of the tracked particles over its initial "
                 "value (eq. 11); anisotropy of the force-carrying contacts between them",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, f"{prefix}_fabric.png"), dpi=110)
    plt.close(fig)
    print(f"figures: {a.figures}/{prefix}_{{layers,front,stress,fabric}}.png")

if __name__ == "__main__":
    sys.exit(main())
