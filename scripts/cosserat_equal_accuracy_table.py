"""Medians and ratios of the logs of scripts/cosserat_equal_accuracy.sh, and the CSV of the
speed_error_plot example.

usage: python cosserat_equal_accuracy_table.py LOG [LOG ...] [--csv OUT.csv [--keep OLD.csv CODE[=NEW] ...]]

Prints, per code and level, the median of assembly + solve (s) with its spread and the SCF
error, then the peer / porofrac ratios of the medians. With --csv, writes one row per code
and level (the medians; columns code,level,cells,dofs,t_assemble,t_solve,t_total,scf,
err_rel) and appends the rows of OLD.csv whose code is CODE, renamed NEW (e.g. the FEniCSx
rows of an earlier round: `--keep docs/data/cosserat_rounds.csv fenicsx-p2p1`).
"""
import collections
import statistics as st
import sys


def main():
    args = sys.argv[1:]
    out, keep = None, []
    if "--csv" in args:
        i = args.index("--csv")
        out, rest, args = args[i + 1], args[i + 2:], args[:i]
        while rest and rest[0] == "--keep":
            old, codes = rest[1], []
            rest = rest[2:]
            while rest and rest[0] != "--keep":
                codes.append(rest.pop(0))
            keep.append((old, codes))
    rows = collections.defaultdict(list)
    for path in args:
        for line in open(path):
            if line.startswith("CSV "):
                f = line[4:].split()[0].split(",")
                rows[(f[0], int(f[1]))].append(f)
    med = {}
    for (code, lev), v in sorted(rows.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        t = [float(x[6]) for x in v]
        m = st.median(t)
        med[(code, lev)] = (m, v)
        print(f"{code:28s} level {lev:<3d} {v[0][2]:>6s} triangles, n {len(v)}: median {m:.4f} s "
              f"(min {min(t):.4f}, max {max(t):.4f}), SCF error {100 * float(v[0][8]):+.3f} %")
    for lev in sorted({lev for _, lev in med}):
        for base in ("porofrac-command", "porofrac"):
            for peer in ("python-dem", "python-dem-smallest-weight"):
                if (base, lev) in med and (peer, lev) in med:
                    print(f"level {lev}: {peer} / {base} = {med[(peer, lev)][0] / med[(base, lev)][0]:.2f}x")
    if out:
        with open(out, "w") as f:
            f.write("code,level,cells,dofs,t_assemble,t_solve,t_total,scf,err_rel\n")
            for (code, lev), (m, v) in sorted(med.items()):
                ta = st.median(float(x[4]) for x in v)
                ts = st.median(float(x[5]) for x in v)
                f.write(",".join([code, str(lev), v[0][2], v[0][3], f"{ta:.6f}", f"{ts:.6f}",
                                  f"{m:.6f}", v[0][7], v[0][8]]) + "\n")
            for old, codes in keep:
                names = dict(c.split("=") if "=" in c else (c, c) for c in codes)
                for line in list(open(old))[1:]:
                    c = line.split(",")[0]
                    if c in names:
                        f.write(names[c] + line[len(c):])
        print(f"-> {out}")


if __name__ == "__main__":
    main()
