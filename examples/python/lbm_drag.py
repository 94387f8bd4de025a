#!/usr/bin/env python3
"""Drag on a cylinder in a channel (the Schäfer–Turek 2D-1 benchmark,
scenes/lbm/schaefer_turek_2d1.toml) over the lattice spacing.

The steady drag coefficient c_D = 2 F_x / (ρ U_mean² D) (U_mean = 0.2 m/s, D = 0.1 m,
ρ = 1 kg/m³) at the end of each run is compared with the benchmark's 5.57953523384
(John 2004); the velocity field of the finest run is kept as a numpy array
(`result.lattice()["vx"]`, shape (ny, nx)). Writes drag.png. Usage, from the workspace root:

    python examples/python/lbm_drag.py [--small] [--out DIR]

--small (or POROFRAC_EXAMPLES_SMALL=1) runs one coarse lattice to t = 2 s.
"""

import argparse
import os
import pathlib

import porofrac

ROOT = pathlib.Path(__file__).resolve().parents[2]
CD_REFERENCE = 5.57953523384
RHO, U_MEAN, D = 1.0, 0.2, 0.1


def drag(spacing, end_time=None):
    """c_D at the end of a run with the given lattice spacing (m), and the result."""
    scene = porofrac.Scene.load(ROOT / "scenes" / "lbm" / "schaefer_turek_2d1.toml")
    scene.set("lbm.spacing", spacing).set("output.vtk", False).set("output.plots", False)
    if end_time is not None:
        scene.set("schedule.end_time", end_time)
    r = scene.run(progress=False)
    fx = r.probes["drag"][-1]
    return 2 * fx / (RHO * U_MEAN**2 * D), r


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", action="store_true", default=bool(os.environ.get("POROFRAC_EXAMPLES_SMALL")))
    ap.add_argument("--out", default=".")
    args = ap.parse_args()
    spacings = [0.01] if args.small else [0.01, 0.005, 0.0025]
    end = 2.0 if args.small else None
    rows = []
    for h in spacings:
        cd, r = drag(h, end)
        rows.append((h, cd))
        print(f"spacing {h:.4g} m ({round(D / h)} nodes across): c_D = {cd:.4f} "
              f"({100 * (cd / CD_REFERENCE - 1):+.2f} % of {CD_REFERENCE})")
    vx = r.lattice()["vx"]
    print(f"velocity field {vx.shape}, largest vx {vx.max():.4f} m/s")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return rows
    fig, (a, b) = plt.subplots(2, 1, figsize=(6, 5))
    a.plot([D / h for h, _ in rows], [cd for _, cd in rows], "o-", label="porofrac lbm")
    a.axhline(CD_REFERENCE, color="k", lw=0.8, label="reference")
    a.set_xlabel("nodes across the cylinder")
    a.set_ylabel("c_D")
    a.legend()
    b.imshow(vx, origin="lower", extent=[0, 2.2, 0, 0.41])
    b.set_title("vx [m/s], finest lattice")
    fig.tight_layout()
    fig.savefig(pathlib.Path(args.out) / "drag.png", dpi=120)
    return rows


if __name__ == "__main__":
    main()
