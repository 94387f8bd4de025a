#!/usr/bin/env python3
"""The seed's hydraulic fracture (scenes/hydrofrac_seed.toml) over the stress ratio.

The right side (xmax), a roller in the scene, becomes a traction −ratio · 10 MPa, so the
horizontal stress is `ratio` times the vertical 10 MPa. Each ratio runs in its own process
(a run already uses every core in its solvers; processes spread whole runs). The breakdown
pressure is the peak of the well pressure; breakdown.png plots it against the ratio.
Usage, from the workspace root:

    python examples/python/hydrofrac_sweep.py [--small] [--workers N] [--out DIR]

--small (or POROFRAC_EXAMPLES_SMALL=1) runs two ratios to t = 600 s.
"""

import argparse
import os
import pathlib
from concurrent.futures import ProcessPoolExecutor

import porofrac

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "hydrofrac_seed.toml"
SV = 1.0e7  # vertical stress (Pa), the scene's traction on ymax


def breakdown(ratio, end_time=None):
    """Run the scene with σh = ratio · σv; returns (ratio, peak well pressure [Pa],
    fractured cells)."""
    scene = porofrac.Scene.load(SCENE)
    scene.set("bc.2", {"boundary": "xmax", "traction": [-ratio * SV, 0.0]})
    if end_time is not None:
        scene.set("schedule.end_time", end_time)
    r = scene.run(progress=False)
    return ratio, float(r.probes["p_well"].max()), r.summary.get("fractured_cells", 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", action="store_true", default=bool(os.environ.get("POROFRAC_EXAMPLES_SMALL")))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=".")
    args = ap.parse_args()
    ratios = [0.6, 0.9] if args.small else [0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
    end = 600.0 if args.small else None
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        rows = sorted(pool.map(breakdown, ratios, [end] * len(ratios)))
    print("ratio  breakdown pressure [MPa]  fractured cells")
    for ratio, p, n in rows:
        print(f"{ratio:5.2f}  {p / 1e6:24.4f}  {n:15d}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return rows
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot([r[0] for r in rows], [r[1] / 1e6 for r in rows], "o-")
    ax.set_xlabel("stress ratio σh / σv")
    ax.set_ylabel("breakdown pressure [MPa]")
    ax.set_title("hydrofrac_seed: breakdown pressure")
    fig.tight_layout()
    fig.savefig(pathlib.Path(args.out) / "breakdown.png", dpi=120)
    return rows


if __name__ == "__main__":
    main()
