#!/usr/bin/env python3
"""Mandel's problem (scenes/mandel.toml) with numpy/scipy: the same discretization as
porofrac, one sparse LU of the monolithic Biot matrix and a back-solve per step.

Quarter domain [0, a] x [0, b] in nx x ny squares. Mechanics: first-order VEM, plane
strain; on a square of side h with node normals N_i (half the outward normals of its two
edges), the local matrix is A = A_c + alpha (I - P)^T (I - P) (x) I_2 with
A_c[(j,a),(k,b)] = (lam N_ja N_kb + mu N_jb N_ka + mu N_j.N_k delta_ab)/|K|,
P_ij = 1/n + d_i.N_j/|K| (d_i = x_i - vertex average) and MRST's
alpha = |K| (D11 + D22 + 2 D33)/(2 sum_i |d_i|^2), D the Kelvin stiffness. Rollers on
x = 0 and y = 0; the top nodes share one vertical displacement (rigid platen) loaded by
-F. Flow: TPFA, T = k h/h on interior faces, 2k on the drained faces x = a (p = 0),
accumulation |K| phi c_f. Coupling C[K,(i,a)] = alpha_B N_ia. Implicit Euler; unknowns
x and q = p/s (s = mean diag K / mean |C|):

    [  K     -s C^T        ] [x]   [ g                            ]
    [ -s C   -s^2 (M + dt A)] [q] = [ -s (C x^n + M p^n)          ]

Prints `RESULT {json}`: the phase times (s; `total_s` from the start of the assembly to
the last back-solve, the interpreter start and the imports excluded), the factor size,
and the pressure at the probe cells of the scene and the platen displacement at the
scene's output times (every tenth step), for comparison with porofrac's probes.csv
(`compare.py`).
"""

import json
import sys
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

# Scene values (scenes/mandel.toml).
A_HALF, B_HEIGHT, NX, NY = 1.0, 1.0, 40, 40
E, NU, ALPHA_B, PHI, PERM, VISC, CF = 1e9, 0.25, 1.0, 0.3, 1e-12, 1e-3, 1e-9
FORCE, DT, STEPS = 1e6, 0.01, 200
PROBE_X = [0.0125, 0.1375, 0.2625, 0.3875, 0.5125, 0.6375, 0.7625, 0.8875, 0.9875]
PROBE_Y = 0.5125
REPORT_EVERY = 10
# "symmetric": minimum degree on A + A^T, no pivoting (the matrix is symmetric
# quasi-definite); "default": SuperLU's defaults (COLAMD, partial pivoting).
SPLU = sys.argv[sys.argv.index("--splu") + 1] if "--splu" in sys.argv else "symmetric"


def local_vem(h, lam, mu):
    """8 x 8 VEM stiffness of an h x h square, nodes counter-clockwise from (0, 0)."""
    x = np.array([[0.0, 0.0], [h, 0.0], [h, h], [0.0, h]])
    vol, n = h * h, 4
    edge = np.roll(x, -1, axis=0) - x  # edge i: node i -> i + 1
    out = np.column_stack([edge[:, 1], -edge[:, 0]])  # outward normal x length
    normals = 0.5 * (out + np.roll(out, 1, axis=0))
    ac = np.zeros((8, 8))
    for j in range(n):
        for k in range(n):
            nj, nk = normals[j], normals[k]
            blk = lam * np.outer(nj, nk) + mu * np.outer(nk, nj) + mu * nj.dot(nk) * np.eye(2)
            ac[2 * j:2 * j + 2, 2 * k:2 * k + 2] = blk / vol
    d = x - x.mean(axis=0)
    proj = 1.0 / n + d @ normals.T / vol
    q = np.eye(n) - proj
    kel = np.array([[lam + 2 * mu, lam, 0], [lam, lam + 2 * mu, 0], [0, 0, 2 * mu]])
    stab = vol * (kel[0, 0] + kel[1, 1] + 2 * kel[2, 2]) / (2 * (d ** 2).sum())
    return ac + stab * np.kron(q.T @ q, np.eye(2)), normals


def main():
    t_start = time.perf_counter()
    h = A_HALF / NX
    assert abs(B_HEIGHT / NY - h) < 1e-15, "square cells"
    lam = E * NU / ((1 + NU) * (1 - 2 * NU))
    mu = E / (2 * (1 + NU))
    nn, nc = (NX + 1) * (NY + 1), NX * NY
    ci, cj = np.meshgrid(np.arange(NX), np.arange(NY), indexing="xy")
    ci, cj = ci.ravel(), cj.ravel()  # cell c = j * NX + i
    base = cj * (NX + 1) + ci
    cell_nodes = np.column_stack([base, base + 1, base + NX + 2, base + NX + 1])
    kloc, normals = local_vem(h, lam, mu)

    # Reduced dofs: a map dof -> equation (-1 fixed); all top nodes' uy -> one equation.
    node_i, node_j = np.arange(nn) % (NX + 1), np.arange(nn) // (NX + 1)
    eq = -np.ones(2 * nn, dtype=np.int64)
    free_x = node_i > 0
    free_y = (node_j > 0) & (node_j < NY)
    eq[2 * np.flatnonzero(free_x)] = 0
    eq[2 * np.flatnonzero(free_y) + 1] = 0
    free = np.flatnonzero(eq == 0)
    eq[free] = np.arange(free.size)
    platen = free.size
    eq[2 * np.flatnonzero(node_j == NY) + 1] = platen
    nm = platen + 1

    cell_dofs = np.empty((nc, 8), dtype=np.int64)
    cell_dofs[:, 0::2] = 2 * cell_nodes
    cell_dofs[:, 1::2] = 2 * cell_nodes + 1
    ce = eq[cell_dofs]
    rows = np.repeat(ce, 8, axis=1).ravel()
    cols = np.tile(ce, (1, 8)).ravel()
    vals = np.tile(kloc.ravel(), nc)
    keep = (rows >= 0) & (cols >= 0)
    kmat = sp.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(nm, nm))
    # Coupling C (cells x equations).
    cw = np.tile(ALPHA_B * normals.ravel(), (nc, 1))
    crow = np.repeat(np.arange(nc), 8).reshape(nc, 8)
    keep = ce >= 0
    cmat = sp.csr_matrix((cw[keep], (crow[keep], ce[keep])), shape=(nc, nm))
    # TPFA: interior faces T = k, drained faces (x = a) 2k; divided by viscosity.
    left = np.flatnonzero(ci < NX - 1)
    below = np.flatnonzero(cj < NY - 1)
    fi = np.concatenate([left, below])
    fj = np.concatenate([left + 1, below + NX])
    tf = np.full(fi.size, PERM / VISC)
    diag = np.bincount(fi, tf, nc) + np.bincount(fj, tf, nc)
    diag[ci == NX - 1] += 2 * PERM / VISC
    amat = sp.csr_matrix(
        (np.concatenate([-tf, -tf, diag]),
         (np.concatenate([fi, fj, np.arange(nc)]), np.concatenate([fj, fi, np.arange(nc)]))),
        shape=(nc, nc))
    acc = np.full(nc, h * h * PHI * CF)
    s = kmat.diagonal().mean() / np.abs(cmat.data).mean()
    system = sp.bmat([[kmat, -s * cmat.T], [-s * cmat, -s * s * (sp.diags(acc) + DT * amat)]],
                     format="csc")
    g = np.zeros(nm)
    g[platen] = -FORCE
    t_assembled = time.perf_counter()

    if SPLU == "symmetric":
        lu = splu(system, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                  options={"SymmetricMode": True})
    else:
        lu = splu(system)
    t_factored = time.perf_counter()

    probe_cells = [int(PROBE_Y / h) * NX + int(x / h) for x in PROBE_X]
    x, p = np.zeros(nm), np.zeros(nc)
    rhs = np.empty(nm + nc)
    rhs[:nm] = g
    report = {}
    for n in range(1, STEPS + 1):
        rhs[nm:] = -s * (cmat @ x + acc * p)
        z = lu.solve(rhs)
        x, p = z[:nm], s * z[nm:]
        if n % REPORT_EVERY == 0:
            report[f"{n * DT:.2f}"] = [float(p[c]) for c in probe_cells] + [float(x[platen])]
    t_solved = time.perf_counter()
    res = np.linalg.norm(system @ z - rhs) / np.linalg.norm(rhs)
    result = {
        "splu": SPLU,
        "cells": nc,
        "unknowns": nm + nc,
        "factor_nnz": int(lu.L.nnz + lu.U.nnz - (nm + nc)),
        "assembly_s": t_assembled - t_start,
        "factorization_s": t_factored - t_assembled,
        "solve_s": t_solved - t_factored,
        "total_s": t_solved - t_start,
        "relative_residual_last_step": float(res),
        "probe_x": PROBE_X,
        "probe_names": [f"p_{round(x * 1e4):04d}" for x in PROBE_X] + ["platen_uy"],
        "probes": report,
    }
    print("RESULT " + json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
