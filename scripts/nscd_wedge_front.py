#!/usr/bin/env python3
"""Wedge-front position against wall displacement for a forced-fold run (Renouf et al.
(2006) §5.2, Fig. 7).

    python3 scripts/nscd_wedge_front.py OUT_DIR [LAYER_TOP] [WALL_SPEED] [FRAME_DT]

OUT_DIR is the output directory of `porofrac run scenes/nscd/forced_fold_wedge.toml`
(particle VTK frames `vtk/particles_*.vtp`, binary base64 with UInt64 headers). The free
surface is the highest disk top in bins of 1 m; the front is the first bin to the right
of the moving wall whose surface is below LAYER_TOP + 1 m (about one mean diameter
above the undeformed layer: the toe of the thickened wedge). Prints one line per frame
and the straight-line fit of front against wall displacement with its residuals.
Defaults: the reduced scene's layer top 6 m, wall speed 0.5 m/s, frames every 2.5 s.
"""
import base64
import glob
import re
import struct
import sys


def array(text, name, n, width):
    m = re.search(r'Name="%s"[^>]*>\s*([A-Za-z0-9+/=]+)\s*<' % name, text)
    raw = base64.b64decode(m.group(1))
    return struct.unpack("<%dd" % (n * width), raw[8 : 8 + 8 * n * width])


def main():
    out = sys.argv[1]
    top = float(sys.argv[2]) if len(sys.argv) > 2 else 6.0
    speed = float(sys.argv[3]) if len(sys.argv) > 3 else 0.5
    frame_dt = float(sys.argv[4]) if len(sys.argv) > 4 else 2.5
    rows = []
    for i, f in enumerate(sorted(glob.glob(f"{out}/vtk/particles_*.vtp"))):
        text = open(f).read()
        n = int(re.search(r'NumberOfPoints="(\d+)"', text).group(1))
        xyz = array(text, "Points", n, 3)
        r = array(text, "radius", n, 1)
        surface = {}
        for k in range(n):
            b = int(xyz[3 * k] // 1.0)
            surface[b] = max(surface.get(b, -1e300), xyz[3 * k + 1] + r[k])
        wall = speed * frame_dt * i
        b = int(wall // 1.0) + 1
        while b in surface and surface[b] > top + 1.0:
            b += 1
        rows.append((frame_dt * i, wall, float(b)))
        print(f"t {frame_dt * i:7.1f} s  wall {wall:6.2f} m  front {b:5d} m")
    n = len(rows)
    mw = sum(w for _, w, _ in rows) / n
    mf = sum(f for _, _, f in rows) / n
    slope = sum((w - mw) * (f - mf) for _, w, f in rows) / sum((w - mw) ** 2 for _, w, _ in rows)
    res = [f - (mf + slope * (w - mw)) for _, w, f in rows]
    rms = (sum(x * x for x in res) / n) ** 0.5
    print(f"straight line: slope {slope:.3f}, max |residual| {max(map(abs, res)):.2f} m, rms {rms:.2f} m")


if __name__ == "__main__":
    main()
