#!/usr/bin/env python3
"""Write a synthetic digitised sandstone: a grey-level PNG of a 2D grain pack.

This is a *synthetic* image, not a scan of a real rock: grains are ellipses of random
size, elongation and orientation, with rough outlines (a few random harmonics of the
radius), dropped without overlap by more than a small fraction so the pore space stays
connected, as the grains of Mora et al. (2015, Fig. 10) were shrunk to give a 2D section
the permeability of the 3D rock. Grains are bright (grey 200-240, a little speckle), pores
dark (20-50), as a segmented micro-CT slice; a column band at the left and right is kept
free of grains (the inlet and outlet of the flow).

Usage: scripts/synthetic_sandstone.py [out.png] [--width 200] [--height 100] [--seed 7]
Only the standard library is used (zlib for the PNG stream), so the image is reproduced
bit for bit from the seed.
"""

import argparse
import math
import random
import struct
import zlib


def png_grey(path, width, height, rows):
    """Write an 8-bit greyscale PNG."""

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def grains(width, height, margin, rng, target):
    """Ellipses (cx, cy, a, b, angle, harmonics) until the solid fraction reaches target."""
    placed = []
    area = 0.0
    tries = 0
    while area < target * (width - 2 * margin) * height and tries < 200000:
        tries += 1
        r = rng.uniform(3.0, 9.0)
        e = rng.uniform(1.0, 1.6)
        a, b = r * math.sqrt(e), r / math.sqrt(e)
        cx = rng.uniform(margin + a, width - margin - a)
        cy = rng.uniform(-0.5 * b, height + 0.5 * b)
        # grains do not touch: a throat of about 3 pixels or more stays between
        # the bounding circles of most pairs
        ok = all(
            math.hypot(cx - g[0], cy - g[1]) > 0.95 * (a + g[2]) + 3.0 for g in placed
        )
        if not ok:
            continue
        harm = [(k, rng.uniform(0.0, 0.12) / k, rng.uniform(0.0, 2 * math.pi)) for k in (2, 3, 5)]
        placed.append((cx, cy, a, b, rng.uniform(0.0, math.pi), harm))
        area += math.pi * a * b
    return placed


def inside(g, x, y):
    cx, cy, a, b, th, harm = g
    dx, dy = x - cx, y - cy
    c, s = math.cos(th), math.sin(th)
    u, v = c * dx + s * dy, -s * dx + c * dy
    rho = math.hypot(u / a, v / b)
    phi = math.atan2(v / b, u / a)
    rough = 1.0 + sum(amp * math.cos(k * phi + ph) for k, amp, ph in harm)
    return rho <= rough


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", default="scenes/lbm/sandstone.png")
    p.add_argument("--width", type=int, default=200)
    p.add_argument("--height", type=int, default=100)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--solid", type=float, default=0.55, help="target solid fraction")
    args = p.parse_args()
    rng = random.Random(args.seed)
    w, h, margin = args.width, args.height, 12
    gs = grains(w, h, margin, rng, args.solid)
    rows = []
    solid = 0
    for r in range(h):
        y = h - 1 - r + 0.5  # row 0 is the top
        row = []
        for c in range(w):
            x = c + 0.5
            near = [g for g in gs if abs(g[0] - x) < g[2] * 1.2 + 1 and abs(g[1] - y) < g[2] * 1.2 + 1]
            if any(inside(g, x, y) for g in near):
                row.append(rng.randint(200, 240))
                solid += 1
            else:
                row.append(rng.randint(20, 50))
        rows.append(row)
    png_grey(args.out, w, h, rows)
    print(f"{args.out}: {w} x {h} pixels, {len(gs)} grains, solid fraction {solid / (w * h):.3f}")


if __name__ == "__main__":
    main()
