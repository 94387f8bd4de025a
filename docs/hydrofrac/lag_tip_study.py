"""The crack tip of scenes/hydrofrac_seed_fluid_lag.toml at the written times, from a run's
VTK files (docs/hydrofrac/validation.md, "What makes the reach grid dependent").

    python3 docs/hydrofrac/lag_tip_study.py OUT [OUT...] [--p-cav 2300]

OUT is a run's output folder (e.g. refine_24/out of scripts/hydrofrac_refinement.sh). For
every written time after the first and for each wing of the crack along x = 15 m (up:
y > 15 m, down: y < 15 m) it prints:

* the reach: the largest distance of a fractured centroid from the well centre (15, 15);
* the stress intensity read from the opening behind the tip,
  K_I = E' w(r) / (4 sqrt(2/pi) sqrt(r)) with E' = E / (1 - nu^2) = 1.1 GPa, where w(r) is
  the mean u_x of the nodes 0.15-0.25 m right of x = 15 m minus that of the nodes
  0.15-0.25 m left of it, within 0.04 m of the line at the distance r behind the last
  failed cell of the wing, for r = 0.1, 0.2, 0.3, 0.5 m;
* the cells of the wing held at the cavitation pressure (p <= p_cav (1 + 1e-9), the well
  cells excepted): their number and area (the cavitated region);
* the lag: how far the farthest of those cells lies beyond the reach.

Reads the binary (base64, UInt64 header, uncompressed) .vtu files porofrac writes; needs
numpy.
"""
import base64, glob, math, re, sys

import numpy as np

E, NU = 1.0e9, 0.3
EP = E / (1 - NU * NU)
CX, CY = 15.0, 15.0
TYPES = {"Float64": "<f8", "Int32": "<i4", "Int64": "<i8", "UInt8": "u1"}


def arrays(path):
    """The data arrays of a .vtu file by name."""
    text = open(path, "rb").read().decode()
    out = {}
    pattern = (r'<DataArray type="(\w+)" Name="([^"]+)"[^>]*format="binary">\s*'
               r'([A-Za-z0-9+/=\s]+?)\s*</DataArray>')
    for m in re.finditer(pattern, text):
        raw = base64.b64decode("".join(m.group(3).split()))
        out[m.group(2)] = np.frombuffer(raw[8:], dtype=TYPES[m.group(1)])
    return out


def study(out, p_cav):
    files = sorted(glob.glob(f"{out}/vtk/step_*.vtu"))
    if not files:
        sys.exit(f"no VTK files in {out}/vtk")
    first = arrays(files[0])
    pts = first["Points"].reshape(-1, 3)[:, :2]
    conn, ends = first["connectivity"], first["offsets"]
    starts = np.concatenate([[0], ends[:-1]])
    cells = [conn[s:e] for s, e in zip(starts, ends)]
    cen = np.array([pts[c].mean(axis=0) for c in cells])
    area = np.array([
        0.5 * abs(np.dot(pts[c, 0], np.roll(pts[c, 1], -1)) - np.dot(pts[c, 1], np.roll(pts[c, 0], -1)))
        for c in cells
    ])
    dist = np.hypot(cen[:, 0] - CX, cen[:, 1] - CY)
    well = first["tag:well"] > 0
    print(out)
    for k, f in enumerate(files[1:], start=1):
        a = arrays(f)
        failed = a["fractured"] > 0
        p = a["pressure"]
        u = a["displacement"].reshape(-1, 3)[:, :2]
        cav = (p <= p_cav * (1 + 1e-9)) & ~well
        for sign, name in ((1, "up"), (-1, "down")):
            side = sign * (cen[:, 1] - CY) > 0
            wing = failed & side
            if not wing.any():
                print(f"  step {k}: {name}: no crack")
                continue
            reach = dist[wing].max()
            tip_y = cen[wing, 1].max() if sign > 0 else cen[wing, 1].min()
            ks = []
            for r in (0.1, 0.2, 0.3, 0.5):
                y = tip_y - sign * r
                row = np.abs(pts[:, 1] - y) < 0.04
                left = row & (pts[:, 0] > CX - 0.25) & (pts[:, 0] < CX - 0.15)
                right = row & (pts[:, 0] > CX + 0.15) & (pts[:, 0] < CX + 0.25)
                if not (left.any() and right.any()):
                    ks.append(float("nan"))
                    continue
                w = u[right, 0].mean() - u[left, 0].mean()
                ks.append(EP * w / (4 * math.sqrt(2 / math.pi) * math.sqrt(r)))
            held = cav & side
            lag = dist[held].max() - reach if held.any() else float("nan")
            k_text = " / ".join(f"{x / 1e6:.2f}" for x in ks)
            print(f"  step {k}: {name}: reach {reach:.3f} m, K_I at r = 0.1/0.2/0.3/0.5 m: "
                  f"{k_text} MPa m^0.5, cells at the bound {held.sum()} ({area[held].sum():.2e} m2), "
                  f"lag {lag:.3f} m")


def main():
    args = sys.argv[1:]
    p_cav = 2.3e3
    if "--p-cav" in args:
        i = args.index("--p-cav")
        p_cav = float(args[i + 1])
        del args[i:i + 2]
    if not args:
        sys.exit(__doc__)
    for out in args:
        study(out, p_cav)


if __name__ == "__main__":
    main()
