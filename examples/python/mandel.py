#!/usr/bin/env python3
"""Mandel's problem (scenes/mandel.toml) against its closed form.

The centre pressure of a poroelastic specimen squeezed between rigid platens rises above
its undrained value before it decays (the Mandel–Cryer effect). The run's probes along
y = b/2 are compared with Abousleiman et al. (1996):

    p(x, t) = 2 p0 Σ sin βn / (βn − sin βn cos βn) (cos(βn x / a) − cos βn) exp(−βn² c t / a²)

with tan βn = (1 − ν)/(νu − ν) βn. Prints the largest error relative to p0 and writes
mandel.png (pressure profiles, run and closed form). Usage, from the workspace root:

    python examples/python/mandel.py [--small] [--out DIR]

--small (or POROFRAC_EXAMPLES_SMALL=1) runs a coarser grid to t = 0.5 s.
"""

import argparse
import os
import pathlib

import numpy as np

import porofrac

ROOT = pathlib.Path(__file__).resolve().parents[2]

# The scene's material, as its header derives them.
A, F = 1.0, 1.0e6
E, NU, PHI, CF, K_PERM, MU = 1.0e9, 0.25, 0.3, 1.0e-9, 1.0e-12, 1.0e-3
G = E / (2 * (1 + NU))
K = E / (3 * (1 - 2 * NU))
M = 1 / (PHI * CF)
KU = K + M
B = M / KU
NU_U = (3 * KU - 2 * G) / (2 * (3 * KU + G))
C = (K_PERM / MU) * M * (K + 4 * G / 3) / (KU + 4 * G / 3)
P0 = F * B * (1 + NU_U) / (3 * A)


def roots(n=200):
    """The first n positive roots of tan β = (1 − ν)/(νu − ν) β, by bisection."""
    k = (1 - NU) / (NU_U - NU)
    f = lambda b: np.tan(b) - k * b
    out = []
    for i in range(n):
        lo, hi = i * np.pi + 1e-9, i * np.pi + np.pi / 2 - 1e-9
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if np.sign(f(mid)) == np.sign(f(lo)):
                lo = mid
            else:
                hi = mid
        out.append(0.5 * (lo + hi))
    return np.array(out)


def pressure(x, t, beta=roots()):
    """The closed-form pressure at x (m) and t > 0 (s), Pa."""
    s = np.sin(beta) / (beta - np.sin(beta) * np.cos(beta))
    terms = s[:, None] * (np.cos(np.outer(beta, x) / A) - np.cos(beta)[:, None])
    return 2 * P0 * (terms * np.exp(-(beta**2) * C * t / A**2)[:, None]).sum(axis=0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", action="store_true", default=bool(os.environ.get("POROFRAC_EXAMPLES_SMALL")))
    ap.add_argument("--out", default=".")
    args = ap.parse_args()
    scene = porofrac.Scene.load(ROOT / "scenes" / "mandel.toml")
    if args.small:
        scene.set("grid.cells", [40, 8]).set("schedule.end_time", 0.5)
    r = scene.run(progress=not args.small)
    names = [n for n in r.probes if n.startswith("p_")]
    x = np.array([float("0." + n[2:]) for n in names])
    t = r.probes["time"]
    worst = 0.0
    for i, ti in enumerate(t):
        if ti < 0.05:
            continue
        run = np.array([r.probes[n][i] for n in names])
        worst = max(worst, np.abs(run - pressure(x, ti)).max() / P0)
    print(f"p0 = {P0:.6g} Pa, c = {C:.5g} m²/s; largest error {100 * worst:.2f} % of p0")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return worst
    fig, ax = plt.subplots(figsize=(6, 4))
    xs = np.linspace(0, A, 101)
    for i in range(1, len(t), max(1, len(t) // 5)):
        line = ax.plot(xs, pressure(xs, t[i]) / P0, lw=1)[0]
        ax.plot(x, [r.probes[n][i] / P0 for n in names], "o", ms=3, color=line.get_color(), label=f"t = {t[i]:.2g} s")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("p / p0")
    ax.set_title("Mandel's problem: run (dots) and closed form (lines)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(pathlib.Path(args.out) / "mandel.png", dpi=120)
    return worst


if __name__ == "__main__":
    main()
