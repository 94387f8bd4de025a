"""The convergence plot of docs/models/cosserat.md: the stress concentration factor error on
the plate with a hole (signed) and the L2 errors on the shear layer against the cell size, one
curve per stencil rule (and strain variant for the shear layer).

usage: python cosserat_convergence_plot.py SCF.csv SHEAR.csv OUT.png

SCF.csv (mesh,rule,cells,scf,err_pct; meshes m* Gmsh, o* O-grid) is the table of
`plate_hole run FILE 0.216 2 0.6 auto single RULE` against the converged 2.5641; SHEAR.csv
is written by `cargo run --release -p porofrac-cosserat --example convergence SHEAR.csv`.
Needs numpy and matplotlib.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

AREA = 16.2 ** 2 - np.pi * 0.216 ** 2 / 4  # the quarter plate, mm²
STYLE = {"smallest-boundary-weight": ("C0", "o", "smallest-boundary-weight (default)"),
         "first-interpolating": ("C1", "s", "first-interpolating (seed)"),
         "smallest-weight": ("C2", "^", "smallest-weight (paper's pool)")}


def main():
    scf_path, shear_path, out = sys.argv[1:4]
    scf = list(csv.DictReader(open(scf_path)))
    shear = list(csv.DictReader(open(shear_path)))
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    for rule, (col, mk, label) in STYLE.items():
        for fam, ls, name in (("m", "-", "Gmsh"), ("o", "--", "O-grid")):
            rows = [r for r in scf if r["rule"] == rule and r["mesh"].startswith(fam)]
            h = np.array([np.sqrt(AREA / float(r["cells"])) for r in rows])
            e = np.array([float(r["err_pct"]) for r in rows])
            ax[0].semilogx(h, e, ls, color=col, marker=mk, label=f"{label}, {name}")
    ax[0].axhline(0.0, color="grey", lw=0.8)
    ax[0].set_xlabel("mean cell size √(|Ω|/cells) (mm)")
    ax[0].set_ylabel("SCF error against 2.5641 (%)")
    ax[0].set_title("plate with a hole, N = 0.6, r/ℓ = 2")
    ax[0].legend(fontsize=7)
    for k, (key, what) in enumerate((("err_u", "u₁"), ("err_phi", "φ"))):
        a = ax[k + 1]
        for rule, (col, mk, label) in STYLE.items():
            for strain, ls in (("facet", "-"), ("cell", "--")):
                rows = [r for r in shear if r["rule"] == rule and r["strain"] == strain]
                if not rows:
                    continue
                h = np.array([1e3 * float(r["h_mm"]) for r in rows])
                e = np.array([float(r[key]) for r in rows])
                a.loglog(h, e, ls, color=col, marker=mk, label=f"{label}, {strain} rotation")
        h = np.array([6.25, 50.0])
        ref = float([r for r in shear if r["strain"] == "facet"][-1][key])
        a.loglog(h, ref * (h / 6.25) ** 2, ":", color="grey", label="order 2")
        a.set_xlabel("cell size along the layer h/(5n) (µm)")
        a.set_ylabel(f"relative L2 error of {what} (–)")
        a.set_title(f"shear layer, {what}")
        a.legend(fontsize=7, title="default = seed here (same stencils)", title_fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"-> {out}")


if __name__ == "__main__":
    main()
