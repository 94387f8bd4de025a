#!/usr/bin/env python3
"""Predicted time per step (LBM) and per CG iteration (E3) on P = 64 ... 4096 MPI ranks.

The model of docs/mpi-scaling.md: compute from per-core rates measured on this machine,
messages from the halo volumes and counts of porofrac's decompositions, a stated network
(latency ALPHA, bandwidth BANDWIDTH per link), and for the AMG the levels kept inside a
rank with the coarsest gathered on every rank. Prints the markdown tables of the doc.

    python3 scripts/mpi_scaling_model.py [ALPHA_US BANDWIDTH_GBS]
"""

import math
import sys

# The network (stated, not measured): an InfiniBand HDR100-class link between nodes.
ALPHA = float(sys.argv[1]) * 1e-6 if len(sys.argv) > 1 else 2.0e-6  # s per message
BANDWIDTH = float(sys.argv[2]) * 1e9 if len(sys.argv) > 2 else 12.5e9  # bytes/s

RANKS = [64, 256, 1024, 4096]

# --- Lattice Boltzmann, D2Q9 AA pattern, slabs of columns (porofrac_lbm::slab) ----------
# Measured: 179.1 MLUPS on one thread, 1024² periodic, quiet (docs/BENCHMARKS.md,
# "Lattice Boltzmann (D2Q9)": the kernel at 0.64 of the copy bandwidth).
LBM_NODES_PER_S = 179.1e6
HALO_COLUMNS = 4  # each side of a window; recomputed by the window's rank
POPULATIONS = 9  # the AA pattern's stored populations, all exchanged
# Measured: 58 176 bytes per step from rank 0 for 200 rows = 4 · 202 · 9 · 8 (summary.json
# mpi.halo_bytes_per_step, docs/BENCHMARKS.md "MPI: the lattice Boltzmann fluid").


def lbm_step(nx, ny, p):
    """Seconds per lattice step of an interior rank of `p` slabs of an nx × ny lattice."""
    owned = nx / p
    window = owned + 2 * HALO_COLUMNS
    compute = window * ny / LBM_NODES_PER_S
    message = HALO_COLUMNS * (ny + 2) * POPULATIONS * 8
    comm = 2 * (ALPHA + message / BANDWIDTH)  # two neighbours, one message each way
    return compute, comm, message


def lbm_tables():
    out = []
    out.append("**LBM, strong scaling** (one 16 384 × 16 384 lattice, 2.7·10⁸ nodes):\n")
    out.append("| P | columns per rank | compute ms | halo bytes per message | exchange ms | efficiency |")
    out.append("|---:|---:|---:|---:|---:|---:|")
    nx = ny = 16384
    serial = nx * ny / LBM_NODES_PER_S
    for p in RANKS:
        c, m, b = lbm_step(nx, ny, p)
        out.append(
            f"| {p} | {nx / p:.0f} | {c * 1e3:.3f} | {b:,} | {m * 1e3:.4f} | {serial / (p * (c + m)):.2f} |"
        )
    out.append("")
    out.append("**LBM, weak scaling** (1 024 × 1 024 nodes per rank, the lattice 1 024·P × 1 024):\n")
    out.append("| P | compute ms | exchange ms | MLUPS per rank | efficiency |")
    out.append("|---:|---:|---:|---:|---:|")
    for p in RANKS:
        c, m, _ = lbm_step(1024 * p, 1024, p)
        per_rank = 1024 * 1024 / (c + m) / 1e6
        out.append(f"| {p} | {c * 1e3:.3f} | {m * 1e3:.4f} | {per_rank:.1f} | {per_rank / (LBM_NODES_PER_S / 1e6):.2f} |")
    return out


# --- E3: CG + smoothed-aggregation AMG, recursive coordinate bisection -----------------
# Measured (docs/BENCHMARKS.md, "E3 on one and two ranks"): 0.183 s per CG iteration on
# 2 ranks of 88 979 unknowns each, under load 8.3–9 on 2 cores; the quiet machine is taken
# as 2.5× faster (the same section: every figure of that round is 2–3× the quiet one).
SECONDS_PER_UNKNOWN_ITER = 0.183 / 88979 / 2.5
# Measured hierarchy of E3 (177 957 → 3 072 → 192): ratios 58 (aggressive) then 16.
COARSENING = [58.0, 16.0]
# Exchanges per CG iteration on each level: the V-cycle's Chebyshev smoother of degree 2
# before and after (4 products), the residual (1), and on the finest level CG's product (1).
EXCHANGES_FINE = 6
EXCHANGES_COARSE = 5
NEIGHBOURS = 26  # a box among boxes: 6 faces, 12 edges, 8 corners
ALLREDUCES = 3  # two dot products and the residual norm
# The gathered coarsest level: every rank solves it with a sparse Cholesky factor whose
# size grows like n^{4/3} (3D nested dissection); constant stated, not measured:
FILL_CONSTANT = 30.0
SECONDS_PER_FACTOR_ENTRY = 2.0e-9  # two triangular solves, one multiply-add per entry each
AGGLOMERATED_COARSE = 300  # the coarsest size when coarse levels leave ranks


def e3_iteration(unknowns_per_rank, p):
    """Seconds per CG iteration on one rank and its parts, for `p` ranks."""
    n = unknowns_per_rank
    compute = 0.0
    halo = 0.0
    levels = []
    for level in range(len(COARSENING) + 1):
        nodes = n / 3
        side = nodes ** (1 / 3)
        ghost_bytes = 6 * side * side * 3 * 8  # six faces' nodes, 3 dofs, f64
        exchanges = EXCHANGES_FINE if level == 0 else EXCHANGES_COARSE
        # Work of a level in proportion to its unknowns (the measured rate is the whole
        # hierarchy's per finest unknown, so coarse levels' work is already in it).
        halo += exchanges * (NEIGHBOURS * ALPHA + ghost_bytes / BANDWIDTH)
        levels.append(n)
        if level < len(COARSENING):
            n = n / COARSENING[level]
    compute = SECONDS_PER_UNKNOWN_ITER * unknowns_per_rank
    coarse = n * p  # the gathered coarsest level
    gather = math.log2(p) * ALPHA + coarse * 8 / BANDWIDTH
    solve = FILL_CONSTANT * coarse ** (4 / 3) * 2 * SECONDS_PER_FACTOR_ENTRY
    allreduce = ALLREDUCES * 2 * math.log2(p) * ALPHA
    # Alternative: the coarse levels agglomerated onto fewer ranks and aggregated further
    # (as PETSc's GAMG and hypre do) until AGGLOMERATED_COARSE unknowns: one more level per
    # factor 16, each a few exchanges of latency-bound messages, and a tiny gathered solve.
    extra = max(0.0, math.log(coarse / AGGLOMERATED_COARSE, 16.0))
    agglomerated = math.ceil(extra) * EXCHANGES_COARSE * (NEIGHBOURS * ALPHA) + (
        math.log2(p) * ALPHA + FILL_CONSTANT * AGGLOMERATED_COARSE ** (4 / 3) * 2 * SECONDS_PER_FACTOR_ENTRY
    )
    return compute, halo, allreduce, gather + solve, coarse, agglomerated


def e3_tables():
    out = []
    for title, per_rank in [
        ("**E3, weak scaling** (88 979 unknowns per rank, as measured on 2 ranks):", lambda p: 88979),
        ("**E3, strong scaling** (n = 320: 3 · 321³ = 9.9·10⁷ unknowns):", lambda p: 3 * 321**3 / p),
    ]:
        out.append(title + "\n")
        out.append(
            "| P | unknowns per rank | compute ms | halo ms | all-reduce ms | coarse (gather + solve) ms | gathered coarse size | time per iteration ms | efficiency | efficiency, coarse levels agglomerated |"
        )
        out.append("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for p in RANKS:
            n = per_rank(p)
            c, h, a, k, coarse, g = e3_iteration(n, p)
            total = c + h + a + k
            eff = c / total
            eff_g = c / (c + h + a + g)
            out.append(
                f"| {p} | {n:,.0f} | {c * 1e3:.2f} | {h * 1e3:.3f} | {a * 1e3:.3f} | {k * 1e3:.2f} | {coarse:,.0f} | {total * 1e3:.2f} | {eff:.2f} | {eff_g:.2f} |"
            )
        out.append("")
    return out


if __name__ == "__main__":
    print(f"Network: latency {ALPHA * 1e6:.1f} µs, bandwidth {BANDWIDTH / 1e9:.1f} GB/s per link.\n")
    print("\n".join(lbm_tables()))
    print()
    print("\n".join(e3_tables()))
