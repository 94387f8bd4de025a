#!/usr/bin/env python3
"""The thrust zone of a forced-fold run against the critical taper (Dahlen 1984):

    python3 scripts/nscd_f1_taper.py OUT_DIR [--scale S] [--speed V] [--every K]
                                     [--phi PHI ...] [--mu-base MU ...]
    python3 scripts/nscd_f1_taper.py --table [--phi PHI ...] [--mu-base MU ...]
    python3 scripts/nscd_f1_taper.py --check

Measured on the particle frames of OUT_DIR (as written by `porofrac run` for
scenes/nscd/forced_fold_*.toml; S = 0.2 for the reduced scene), every K-th frame:

* the settled layer's top h_s: the median over x in [0.8 L, 0.95 L] of the surface (the
  highest disk top in bins one mean diameter wide) at t = 0;
* the toe: the wedge front of gate 1 (scripts/nscd_f1_figures.py: the first bin right
  of the wall whose surface is below the paper's h + one diameter);
* the moved zone's front: the rightmost bin whose layer disks (y0 < h_s) moved on
  average more than 2 % of the wall's travel s (at least 0.1 m);
* the zone's area above h_s between the wall and the toe, A (its envelope: voids
  counted), against the area shortened, A_0 + h_s s (A_0 the same area at t = 0: the
  wedge), so A / (A_0 + h_s s) - 1 is the zone's dilatancy;
* its taper: tan a_A = 2 A / L^2 (the triangle of the same area and length L = toe -
  wall) and the slope of the straight-line fit of the surface over the zone.

The prediction: a wedge of surface slope a over a layer of thickness h_s holding the
area A_0 + h_s s (no dilatancy) reaches from the wall over L = sqrt(2 (A_0 + h_s s) /
tan a), so its toe is at s + L. The critical taper a_c (the smallest stable one, flat
base, dry, no cohesion; Dahlen's exact solution) solves

    a_c = psi_b - psi_0(a_c),
    psi_0(a) = (1/2) asin(sin a / sin phi) - a / 2,
    psi_b = (1/2) asin(sin phi_b / sin phi) - phi_b / 2,   phi_b = atan(mu_b) <= phi,

phi the assembly's friction angle and mu_b the grip the base transmits (a base stronger
than the assembly shears inside it: phi_b is capped at phi). The script prints a_c and
the wall travel (and time) at which the predicted toe reaches W6's left edge (the
paper's x = 588 m, scaled), for each phi and mu_b asked. Nothing is written unless
--plot names a PNG.

--check tests the two functions: a frictionless base stands at a_c = 0; for a small
mu_b the taper is Dahlen's linearised a_c = mu_b / (1 + K), K = 2 sin phi / (1 - sin
phi) (to 1e-3 at mu_b = 0.01); a base stronger than the assembly gives the same a_c as
phi_b = phi; the wall travel s* returned puts the predicted toe on the target (1e-9 m).
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402

from nscd_f1_figures import CELLS, LAYER, SPEED, frames, front, particles, read_probes  # noqa: E402


def critical_taper(phi_deg, mu_b):
    """Dahlen's smallest stable taper (degrees) of a dry cohesionless wedge on a flat
    base: friction angle phi, base friction mu_b (phi_b capped at phi)."""
    phi = math.radians(phi_deg)
    phib = min(math.atan(mu_b), phi)
    psib = 0.5 * math.asin(math.sin(phib) / math.sin(phi)) - 0.5 * phib

    def g(a):
        return a - (psib - (0.5 * math.asin(min(1.0, math.sin(a) / math.sin(phi))) - 0.5 * a))

    lo, hi = 0.0, phi
    if g(lo) > 0 or g(hi) < 0:
        return float("nan")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(mid) > 0:
            hi = mid
        else:
            lo = mid
    return math.degrees(0.5 * (lo + hi))


def toe_reaches(a_deg, area0, h, target):
    """Wall travel s at which s + sqrt(2 (area0 + h s) / tan a) reaches target (m)."""
    t = math.tan(math.radians(a_deg))
    f = lambda s: s + math.sqrt(2.0 * (area0 + h * s) / t) - target
    if f(0.0) >= 0:
        return 0.0
    lo, hi = 0.0, target
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(mid) > 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def surface(x, r, width):
    """Highest disk top per bin of the given width: (bin index array, tops)."""
    b = np.floor(x[:, 0] / width).astype(int)
    top = np.full(b.max() + 1, -np.inf)
    np.maximum.at(top, b, x[:, 1] + r)
    return top


def plot(a, meas, loads, area0, h_s, w6_edge):
    """Toe and moved front against the wall's travel, the cells' loading, the
    predicted toe of a wedge of constant taper."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    m = np.array([(w, toe, mv) for _, w, toe, mv, _ in meas])
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    ax.plot(m[:, 0], m[:, 1], "k.-", label="toe (surface one diameter above h)")
    ax.plot(m[:, 0], m[:, 2], "c.:", label="moved front (layer ux > 2 % of s)")
    for edge, t_load, t_def in loads:
        if np.isfinite(t_load):
            ax.plot([a.speed * t_load], [edge], "rv")
        if np.isfinite(t_def):
            ax.plot([a.speed * t_def], [edge], "bs", mfc="none")
        ax.axhline(edge, color="0.85", lw=0.8)
    ax.plot([], [], "rv", label="cell's left edge: p up 10 %")
    ax.plot([], [], "bs", mfc="none", label="cell's left edge: deformed 2 %")
    s_end = float(m[-1, 0])
    sv = np.linspace(0.0, s_end, 200)
    for alpha, style in ((12.0, "--"), (15.2, "-."), (19.5, ":")):
        t = math.tan(math.radians(alpha))
        ax.plot(sv, sv + np.sqrt(2.0 * (area0 + h_s * sv) / t), "g" + style,
                label=f"toe of a {alpha:g} deg wedge (no dilatancy)")
    ax.axhline(w6_edge, color="r", lw=0.8, label=f"W6's left edge, x = {w6_edge:g} m")
    ax.set_xlabel("wall travel s (m)")
    ax.set_ylabel("x (m)")
    ax.set_title("F1: the thrust zone's toe against the wall's travel ("
                 + os.path.basename(os.path.normpath(a.out)) + ")")
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(a.plot, dpi=110)
    print(f"wrote {a.plot}")


def check():
    """The checks of --check (module docs); raises AssertionError on a miss."""
    for phi in (20.0, 30.0, 40.0):
        sp = math.sin(math.radians(phi))
        k = 2.0 * sp / (1.0 - sp)
        assert abs(critical_taper(phi, 0.0)) < 1e-12
        lin = math.degrees(0.01 / (1.0 + k))
        assert abs(critical_taper(phi, 0.01) / lin - 1.0) < 1e-3, (phi, critical_taper(phi, 0.01), lin)
        strong = critical_taper(phi, 10.0)
        assert abs(strong - critical_taper(phi, math.tan(math.radians(phi)))) < 1e-9
    for a_deg, area0, h, target in ((12.0, 8993.3, 28.1, 588.0), (19.5, 407.0, 4.86, 117.6)):
        sstar = toe_reaches(a_deg, area0, h, target)
        toe = sstar + math.sqrt(2.0 * (area0 + h * sstar) / math.tan(math.radians(a_deg)))
        assert 0.0 < sstar < target and abs(toe - target) < 1e-9, (sstar, toe)
    print("nscd_f1_taper checks: ok")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", nargs="?")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--speed", type=float, default=SPEED)
    ap.add_argument("--every", type=int, default=4)
    ap.add_argument("--phi", type=float, nargs="+", default=[20.0, 25.0, 30.0])
    ap.add_argument("--mu-base", type=float, nargs="+", default=[0.24, 0.4, 0.8])
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--plot", default=None,
                    help="write the toe, the cells' loading and the predicted toes to this PNG")
    a = ap.parse_args()
    if a.check:
        check()
        return
    s = a.scale
    w6_edge = (CELLS[5][0] - CELLS[5][2]) * s
    if a.table or a.out is None:
        print("phi (deg)  mu_b  a_c (deg)")
        for phi in a.phi:
            for mu in a.mu_base:
                print(f"{phi:8.1f}  {mu:5.2f}  {critical_taper(phi, mu):8.2f}")
        if a.out is None:
            return
    rows = frames(a.out)
    x0, r0, u0 = particles(rows[0][1])
    init = x0 - u0
    d = 2.0 * float(np.mean(r0))
    length = float(np.max(init[:, 0] + r0))
    top0 = surface(x0, r0, d)
    far = np.arange(len(top0)) * d
    sel = (far >= 0.8 * length) & (far <= 0.95 * length) & np.isfinite(top0)
    h_s = float(np.median(top0[sel]))
    layer = init[:, 1] < h_s

    def zone(x, r, u, wall):
        top = surface(x, r, d)
        toe = front(x, r, wall, LAYER * s, d)
        xb = (np.arange(len(top)) + 0.5) * d
        inz = (xb > wall) & (xb < toe) & np.isfinite(top)
        area = float(np.sum(np.clip(top[inz] - h_s, 0.0, None)) * d)
        slope = float(-np.polyfit(xb[inz], top[inz], 1)[0]) if np.sum(inz) >= 3 else float("nan")
        # The moved zone: layer disks' mean ux per bin.
        b = np.floor(x[layer, 0] / d).astype(int)
        sums = np.bincount(b, weights=u[layer, 0])
        counts = np.bincount(b)
        mean_ux = np.where(counts > 0, sums / np.maximum(counts, 1), 0.0)
        moved = np.nonzero(mean_ux > max(0.02 * wall, 0.1 * s))[0]
        moved_front = float((moved.max() + 1) * d) if len(moved) else float("nan")
        return toe, area, slope, moved_front

    toe0, area0, _, _ = zone(x0, r0, u0, 0.0)
    print(f"{a.out}: {len(r0)} disks, mean diameter {d:.3f} m, settled layer top h_s = {h_s:.2f} m "
          f"(nominal {LAYER * s:g}), wedge area above it A_0 = {area0:.1f} m^2, toe at t = 0 "
          f"{toe0:.1f} m, W6's left edge {w6_edge:g} m")
    print("t (s)  wall s (m)  toe (m)  moved front (m)  L (m)  A (m^2)  A/(A_0+h_s s)  "
          "taper from area (deg)  surface fit (deg)")
    meas = []
    for k, (t, p, _) in enumerate(rows):
        if k % a.every and k != len(rows) - 1:
            continue
        x, r, u = particles(p)
        wall = a.speed * t
        toe, area, slope, moved = zone(x, r, u, wall)
        L = toe - wall
        shortened = area0 + h_s * wall
        ta = math.degrees(math.atan(2.0 * area / L ** 2)) if L > 0 else float("nan")
        meas.append((t, wall, toe, moved, ta))
        print(f"{t:6.1f}  {wall:9.2f}  {toe:7.1f}  {moved:15.1f}  {L:6.1f}  {area:8.1f}  "
              f"{area / shortened:13.3f}  {ta:21.2f}  {math.degrees(math.atan(slope)):17.2f}")
    print("prediction (no dilatancy): the toe reaches W6's left edge when the wall has "
          "travelled s*")
    print("phi (deg)  mu_b  a_c (deg)  toe at the end (m)  s* (m)  t* (s)")
    end_wall = meas[-1][1]
    for phi in a.phi:
        for mu in a.mu_base:
            ac = critical_taper(phi, mu)
            toe_end = end_wall + math.sqrt(2.0 * (area0 + h_s * end_wall)
                                           / math.tan(math.radians(ac)))
            sstar = toe_reaches(ac, area0, h_s, w6_edge)
            print(f"{phi:8.1f}  {mu:5.2f}  {ac:8.2f}  {toe_end:18.1f}  {sstar:6.1f}  "
                  f"{sstar / a.speed:6.1f}")
    # When each cell is loaded (the 2 s running mean of its p leaves 10 % of its start)
    # and deformed (lambda_x or lambda_y leaves 1 by 2 %), and where the toe is then.
    pr = read_probes(a.out)
    tp = pr["time"]
    n = max(1, int(round(2.0 / float(tp[1] - tp[0])))) if len(tp) > 1 else 1
    mt = np.array([m[0] for m in meas])
    mtoe = np.array([m[2] for m in meas])
    loads = []
    print("cell  x0 - R (m)  p start (kPa)  loaded at t (s)  toe then (m)  deformed at t (s)  "
          "toe then (m)")
    for k in range(6):
        p = pr[f"p_W{k + 1}"]
        mean = np.convolve(p, np.ones(n) / n, mode="valid")
        off = np.nonzero(np.abs(mean / mean[0] - 1.0) > 0.1)[0]
        t_load = float(tp[off[0] + n - 1]) if len(off) else float("nan")
        lam = np.maximum(np.abs(pr[f"dilation_x_W{k + 1}"] - 1.0),
                         np.abs(pr[f"dilation_y_W{k + 1}"] - 1.0))
        de = np.nonzero(lam > 0.02)[0]
        t_def = float(tp[de[0]]) if len(de) else float("nan")
        at = lambda tt: float(np.interp(tt, mt, mtoe)) if np.isfinite(tt) else float("nan")
        loads.append(((CELLS[k][0] - CELLS[k][2]) * s, t_load, t_def))
        print(f"W{k + 1}  {(CELLS[k][0] - CELLS[k][2]) * s:11.1f}  {mean[0] / 1e3:13.1f}  "
              f"{t_load:15.1f}  {at(t_load):12.1f}  {t_def:17.1f}  {at(t_def):12.1f}")
    half = [m[4] for m in meas if m[0] >= 0.5 * meas[-1][0] and m[0] > 0]
    print(f"summary: taper from the area over the second half {np.mean(half):.1f} deg "
          f"({np.min(half):.1f}-{np.max(half):.1f}), W2 lambda_x at t = {tp[-1]:g} s "
          f"{pr['dilation_x_W2'][-1]:.2f}")
    if a.plot:
        plot(a, meas, loads, area0, h_s, w6_edge)
    # The taper that the measured toe implies, at the last frame and at the time the toe
    # passes W6's edge.
    passed = [m for m in meas if m[2] >= w6_edge]
    if passed:
        t, wall, toe, _, ta = passed[0]
        print(f"the measured toe passes W6's left edge by t = {t:g} s (wall {wall:.1f} m, toe "
              f"{toe:.1f} m, the zone's taper from its area {ta:.2f} deg)")
    else:
        print(f"the measured toe stays short of W6's left edge to t = {meas[-1][0]:g} s")


if __name__ == "__main__":
    main()
