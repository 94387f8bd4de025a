#!/usr/bin/env python3
"""Turn the RESULT lines of scripts/cosserat_rounds.sh into a CSV (for the plot) and the
Markdown table of docs/BENCHMARKS.md (section "Cosserat DEM against a Python port and a P2-P1
FEM"). Standard library only.

usage: python3 scripts/cosserat_table.py ROUNDS.txt [CSV]

CSV columns: code,level,cells,dofs,t_assemble,t_solve,t_total,scf,err_rel
(err_rel = (SCF - SCF_ref) / SCF_ref against the Mindlin / Kaloni-Ariman value;
t_total = assembly + solve; for the command, the scene's assembly (which includes the LU
factorisation or the multigrid setup) + solve). Repeated runs of one code and level are
reduced to the run of median total time.
"""
import json
import sys

REF = 2.554819675614425  # hole_scf(0.3, 0.5, 0.216, 0.216 / 1.063), crates/cosserat/src/reference.rs


def gb(r):
    m = r.get("peak_memory_bytes")
    return f"{m / 1e9:.2f}" if m else "—"


def median(runs):
    """The run of median total time (runs: list of rows of one code and level)."""
    return sorted(runs, key=lambda o: o["t_total"])[len(runs) // 2]


def main():
    rows = []
    pending = None
    for line in open(sys.argv[1]):
        if line.startswith("solver "):
            w = line.split()
            pending = dict(solver=w[1], iterations=int(w[3]), residual=float(w[5]))
        if line.startswith("RESULT "):
            r = json.loads(line[7:])
            if pending and r["code"] == "porofrac":
                r.update(pending)
            pending = None
            rows.append(r)
    groups = {}
    for r in rows:
        if r["code"] == "porofrac-command":
            ta, ts = r["t_assembly_and_factor"], r["t_solve"]
        else:
            ta, ts = r["t_assemble"], r["t_solve"]
        o = dict(code=r["code"], level=r["level"], cells=r["cells"], dofs=r["dofs"],
                 t_assemble=ta, t_solve=ts, t_total=ta + ts, scf=r["scf"],
                 err_rel=(r["scf"] - REF) / REF, raw=r)
        groups.setdefault((o["code"], o["level"]), []).append(o)
    by = {k: median(v) for k, v in groups.items()}
    out = sorted(by.values(), key=lambda o: (o["level"], o["code"]))
    if len(sys.argv) > 2:
        with open(sys.argv[2], "w") as f:
            f.write("code,level,cells,dofs,t_assemble,t_solve,t_total,scf,err_rel\n")
            for o in out:
                f.write(f"{o['code']},{o['level']},{o['cells']},{o['dofs']},{o['t_assemble']:.6f},"
                        f"{o['t_solve']:.6f},{o['t_total']:.6f},{o['scf']:.15e},{o['err_rel']:.6e}\n")
    levels = sorted({o["level"] for o in out if o["code"] == "porofrac"})
    print("| level | triangles | DEM dofs | porofrac solver (GMRES its) | porofrac asm / solve (s) "
          "| porofrac peak (GB) | GMRES-AMG solve (s) (its) / peak (GB) | LU solve (s) / peak (GB) "
          "| Python asm / solve (s) | Python peak (GB) "
          "| Python / porofrac | command total (s) / peak (GB) | DEM SCF (err) | SCF rel. diff Python "
          "| FEM dofs | FEM asm / solve (s) | FEM SCF (err) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for L in levels:
        p = by[("porofrac", L)]
        n = len(groups[("porofrac", L)])
        lu = by.get(("porofrac-lu", L))
        am = by.get(("porofrac-gmres-amg", L))
        q = by.get(("python-dem", L))
        c = by.get(("porofrac-command", L))
        f = by.get(("fenicsx-p2p1", L))
        its = p["raw"].get("iterations")
        cell = [str(L), f"{p['cells']:,}", f"{p['dofs']:,}",
                p["raw"].get("solver", "lu") + (f" ({its})" if its else ""),
                f"{p['t_assemble']:.2f} / {p['t_solve']:.2f}" + (f" (median of {n})" if n > 1 else ""),
                gb(p["raw"])]
        cell.append(f"{am['t_solve']:.2f} ({am['raw'].get('iterations')}) / {gb(am['raw'])}" if am else "—")
        cell.append(f"{lu['t_solve']:.2f} / {gb(lu['raw'])}" if lu else "—")
        if q:
            cell += [f"{q['t_assemble']:.2f} / {q['t_solve']:.2f}", gb(q["raw"]),
                     f"{q['t_total'] / p['t_total']:.1f}×"]
        else:
            cell += ["—", "—", "—"]
        cell.append(f"{c['raw']['t_total']:.2f} / {gb(c['raw'])}" if c else "—")
        cell.append(f"{p['scf']:.4f} ({100 * p['err_rel']:+.2f} %)")
        cell.append(f"{abs(q['scf'] - p['scf']) / p['scf']:.0e}" if q else "—")
        if f:
            cell += [f"{f['dofs']:,}", f"{f['t_assemble']:.2f} / {f['t_solve']:.2f}",
                     f"{f['scf']:.4f} ({100 * f['err_rel']:+.3f} %)"]
        else:
            cell += ["—", "—", "—"]
        print("| " + " | ".join(cell) + " |")
    extra = sorted(o["level"] for o in out if o["code"] == "fenicsx-p2p1" and o["level"] not in levels)
    for L in extra:
        f = by[("fenicsx-p2p1", L)]
        print(f"FEM only, level {L}: {f['cells']:,} triangles, {f['dofs']:,} dofs, "
              f"{f['t_assemble']:.3f} / {f['t_solve']:.3f} s, SCF {f['scf']:.4f} ({100 * f['err_rel']:+.3f} %)")


if __name__ == "__main__":
    main()
