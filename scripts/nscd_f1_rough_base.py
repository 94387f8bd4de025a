#!/usr/bin/env python3
"""Write a variant of a forced-fold scene (scenes/nscd/forced_fold_*.toml) on a rough base:
fixed triangular teeth along the base that keep the bottom disks from rolling.

    python3 scripts/nscd_f1_rough_base.py SCENE OUT [--width W] [--height H]

The teeth are `[[wall]]` polygons (W wide, H high, default 1.0 m and 0.25 m: about one
disk diameter and half the smallest radius) side by side from x = 0 to the right end of
the particle polygon, on the flat base wall that stays below them. The particle polygon
and the tracked cells' centres are lifted by H, so the sample and the cells keep their
heights above the teeth's base line. Everything else in the scene is copied unchanged.
"""
import argparse
import re
import sys
import tomllib


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--width", type=float, default=1.0)
    ap.add_argument("--height", type=float, default=0.25)
    a = ap.parse_args()
    if not (a.width > 0 and a.height > 0):
        raise SystemExit("--width and --height must be positive (m)")
    text = open(a.scene).read()
    scene = tomllib.loads(text)
    polygon = scene.get("particles", {}).get("polygon")
    if not polygon:
        raise SystemExit(f"{a.scene}: [particles] has no polygon")
    length = max(p[0] for p in polygon)
    count = int(round(length / a.width))
    if count < 1 or count > 100_000 or abs(count * a.width - length) > 1e-9 * length:
        raise SystemExit(f"{a.scene}: the polygon's length {length:g} m is not a whole number "
                         f"of teeth of {a.width:g} m (at most 100 000)")

    def lift(points):
        return "[" + ", ".join(f"[{x!r}, {y + a.height!r}]" for x, y in points) + "]"

    head, sep, rest = text.partition("[particles]")
    rest, n = re.subn(r"(?m)^polygon = \[.*\]$", "polygon = " + lift(polygon), rest, count=1)
    if n != 1:
        raise SystemExit(f"{a.scene}: the [particles] polygon is not on one line")
    rest = re.sub(r"center = \[([-0-9.eE+]+), ([-0-9.eE+]+)\]",
                  lambda m: f"center = [{m.group(1)}, {float(m.group(2)) + a.height!r}]", rest)
    teeth = "".join(
        f'\n[[wall]]\nname = "tooth{k}"\npolygon = [[{k * a.width!r}, 0.0], '
        f"[{(k + 1) * a.width!r}, 0.0], [{(k + 0.5) * a.width!r}, {a.height!r}]]\n"
        for k in range(count))
    if "\n[contact]" not in rest:
        raise SystemExit(f"{a.scene}: no [contact] table to put the teeth before")
    rest = rest.replace("\n[contact]", teeth + "\n[contact]", 1)
    note = (f"# Rough-base variant written by scripts/nscd_f1_rough_base.py from {a.scene}: "
            f"{count} teeth {a.width:g} m wide and {a.height:g} m high on the base, the "
            f"particles and cells lifted by {a.height:g} m.\n")
    open(a.out, "w").write(note + head + sep + rest)
    print(f"{a.out}: {count} teeth")


if __name__ == "__main__":
    sys.exit(main())
