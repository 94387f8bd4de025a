"""SCF error of the variational Cosserat DEM under one change of method at a time, on the
same meshes (peers/cosserat/dem.py, the plain numpy/scipy implementation of porofrac's
method; its flags are the variants).

usage: python cosserat_variants.py SCF_REF R R_OVER_L N MESH.vtu [MESH.vtu ...] [-- VARIANT ...]

A VARIANT is `name:key=value,key=value` over the keys of dem.DEFAULTS (`base` = none).
Prints one line per mesh and variant: cells, SCF, error relative to SCF_REF (%).
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "peers", "cosserat"))
import dem  # noqa: E402
from vtu import read_triangles  # noqa: E402

# One change at a time from the seed's rule (`seed`: the first subset with max|lambda| < 1
# on every facet); `default` is porofrac's default (boundary facets: the smallest
# max|lambda|).
VARIANTS = [
    "seed:bselect=same",
    "default:",
    "smallest-weight:select=minmax,depth=2,bselect=same",
    "minmax-pool1:select=minmax,bselect=same",
    "interior-minmax-pool2:select=minmax,depth=2,bselect=first",
    "order-id:order=id,bselect=same",
    "quad:select=quad,bselect=same",
    "cell-strain:strain=cell,bselect=same",
    "eta0.5:eta=0.5,bselect=same",
    "eta2:eta=2,bselect=same",
    "hf-max:hf=max,bselect=same",
    "hf-min:hf=min,bselect=same",
    "hf-facet:hf=facet,bselect=same",
    "hf-centres:hf=centres,bselect=same",
    "traction-cell:traction=cell,bselect=same",
]


def parse(v):
    name, _, rest = v.partition(":")
    opt = {}
    for kv in filter(None, rest.split(",")):
        k, val = kv.split("=")
        opt[k] = type(dem.DEFAULTS[k])(val)
    if opt.get("bselect") == "same" and "select" not in opt:
        opt["select"] = "first"
    return name, opt


def main():
    args = sys.argv[1:]
    variants = VARIANTS
    if "--" in args:
        i = args.index("--")
        args, variants = args[:i], args[i + 1:]
    ref, r, rl, n = map(float, args[:4])
    for path in args[4:]:
        pts, tri = read_triangles(path)
        for v in variants:
            name, opt = parse(v)
            out = dem.solve(pts, tri, r, rl, n, opt)
            err = 100.0 * (out["scf"] / ref - 1.0)
            print(f"{os.path.basename(path)} {out['cells']:7d} {name:16s} {out['scf']:.5f} {err:+.3f} %",
                  flush=True)


if __name__ == "__main__":
    main()
