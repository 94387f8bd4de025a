"""The variational DEM for Cosserat media (seed 001.2) written plainly in numpy/scipy: the
same method as porofrac-cosserat (crates/cosserat), for the plate with a hole (E2).

usage: python dem.py MESH.vtu R R_OVER_L N [--order ..] [--select ..] [--bselect ..]
       [--depth ..] [--strain ..] [--eta ..] [--hf ..] [--traction ..]

The flags switch one choice of the method at a time (`python dem.py -h`); without them it
is porofrac's default method.

Reads a triangle mesh written by porofrac (`plate_hole mesh ...`), solves the quarter plate
16.2 mm with a hole of radius R (mm), G = 1000 MPa, nu = 0.3, Gc = G N^2/(1 - N^2),
l = R / R_OVER_L, traction (0, 1) on y = max, u1 = phi = 0 on x = min, u2 = phi = 0 on
y = min (non-symmetric penalty-free Nitsche), and prints one line

    RESULT {"code": "python-dem", "cells": .., "dofs": .., "nnz": .., "scf": ..,
            "t_read": .., "t_recon": .., "t_assemble": .., "t_solve": ..}

t_assemble includes the reconstruction (t_recon is its part); t_solve is scipy's
sparse direct solver (`spsolve`, SuperLU with its default COLAMD ordering).

The method, as in crates/cosserat/src/{recon.rs, discrete.rs, material.rs}:
* facet values (eqs. 8-10): for each facet, a pool of cells (interior facet: its two cells
  and their face neighbours; boundary facet: cells within graph distance 2), sorted by the
  distance of the barycentre to the facet centroid (ties by cell id), at most 12; the
  3-subsets in lexicographic order, singular ones skipped (|det| <= 1e-10 |e1||e2|); on
  an interior facet the first with max|lambda| < 1 is taken, otherwise the one with the
  smallest max|lambda| < 10; on a boundary facet the one with the smallest max|lambda| (the
  `smallest-boundary-weight` rule); if none, the pool grows by one graph level (twice at most);
* Stokes gradients (11): G_K = (1/|K|) sum_F |F| w_F n_KF;
* strain (12) with the Crouzeix-Raviart facet rotation at the three facet midpoints (weight
  |K|/3 each) and the elastic form (13) as sum_q B_q^T A B_q (the R^T A R form);
* interior penalty (17) weighted by the law, (1/h_F) int_F ([w] x n):A:([w] x n), h_F the mean
  cell diameter, 2-point Gauss on the facet, [w] the jump of the cellwise P1 reconstruction (14);
* Nitsche (18)-(20), penalty-free, non-symmetric, with the cell-mean stress of the facet's
  cell and the facet values (homogeneous data here, so no right-hand side);
* traction tested with the facet values; SCF = max over cells of the mean sigma_22.
"""
import json
import resource
import sys
import time
from itertools import combinations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from vtu import read_triangles

MAX_WEIGHT = 10.0
# The choices of the method (command-line flags --order, --select, --depth, --strain, --eta,
# --hf, --traction); these values are porofrac's.
DEFAULTS = {"order": "distance", "select": "first", "depth": 1, "strain": "facet", "eta": 1.0,
            "hf": "mean", "traction": "facet", "bselect": "minmax"}
MAX_POOL = 12
SIDE, G, NU = 16.2, 1e3, 0.3


# ----------------------------------------------------------------------------- mesh
def mesh_topology(pts, tri):
    """Edges (faces) of a triangle mesh: face nodes, face cells (second -1 on the
    boundary) and the three faces of each cell in the cell's edge order."""
    nc = len(tri)
    e = np.stack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]], axis=1).reshape(-1, 2)
    key = np.sort(e, axis=1)
    uniq, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    cell_faces = inv.reshape(nc, 3)
    nf = len(uniq)
    owner = np.repeat(np.arange(nc), 3)
    face_cells = -np.ones((nf, 2), dtype=np.int64)
    order = np.argsort(inv, kind="stable")
    f_sorted = inv[order]
    starts = np.searchsorted(f_sorted, np.arange(nf))
    face_cells[:, 0] = owner[order[starts]]
    counts = np.bincount(inv, minlength=nf)
    two = counts == 2
    face_cells[two, 1] = owner[order[starts[two] + 1]]
    face_nodes = e[first]
    return face_nodes, face_cells, cell_faces


def _norm(v):
    return np.sqrt(v[..., 0] * v[..., 0] + v[..., 1] * v[..., 1])


def geometry(pts, tri, face_nodes, face_cells, cell_faces):
    """Cell centroids and areas, facet centroids, lengths and unit normals (from
    face_cells[:, 0] outwards), with the formulas of porofrac's grid (crates/grid builder:
    centroids from the first moments of the boundary facets), so that the tie-breaks of
    the stencil pools (equal distances on symmetric cells) fall the same way."""
    pa, pb = pts[face_nodes[:, 0]], pts[face_nodes[:, 1]]
    e = pb - pa
    avec = np.stack([e[:, 1], -e[:, 0]], axis=1)
    area = _norm(avec)
    normal = avec / area[:, None]
    w = avec[:, 0] * normal[:, 0] + avec[:, 1] * normal[:, 1]
    fc = (0.5 * (pa + pb) * w[:, None]) / w[:, None]
    P = pts[tri]
    xc = ((P[:, 0] + P[:, 1]) + P[:, 2]) / 3.0
    vol = np.zeros(len(tri))
    moment = np.zeros((len(tri), 2))
    for i in range(3):  # the cell's edges in loop order (counter-clockwise: outward)
        a, b = P[:, i], P[:, (i + 1) % 3]
        ct = (a + b) / 2.0
        ed = b - a
        dx = ct - xc
        v = (ed[:, 1] * dx[:, 0] + (-ed[:, 0]) * dx[:, 1]) / 2.0
        vol += v
        moment += (xc + ct * 2.0) * (v / 3.0)[:, None]
    cc = moment / vol[:, None]
    flip = ((fc - cc[face_cells[:, 0]]) * normal).sum(1) < 0
    normal[flip] *= -1
    return cc, vol, fc, area, normal


# ----------------------------------------------------------------------------- reconstruction
_COMBOS = {p: np.array(list(combinations(range(p), 3)), dtype=np.int64) for p in range(3, MAX_POOL + 1)}


def best_subset(pool, cc, xf, select="first"):
    """Barycentric weights of xf in every 3-subset of the pool (lexicographic order, 2x2
    Gaussian elimination with partial pivoting as in recon.rs), then the selection rule:
    `first` takes the first subset with max|lambda| < 1 (else the smallest max|lambda| < 10),
    `minmax` the subset with the smallest max|lambda| of all (the first of equals), `quad`
    the subset with the smallest sum |lambda_c| |x_c - x_F|^2 (the bound of the facet value's
    error on quadratic fields) among those with max|lambda| < 10."""
    p = len(pool)
    if p < 3:
        return None
    idx = pool[_COMBOS[p]]
    x0 = cc[idx[:, 0]]
    c1 = cc[idx[:, 1]] - x0
    c2 = cc[idx[:, 2]] - x0
    r = xf - x0
    scale = np.sqrt(c1[:, 0] * c1[:, 0] + c1[:, 1] * c1[:, 1]) * np.sqrt(c2[:, 0] * c2[:, 0] + c2[:, 1] * c2[:, 1])
    # rows of E: [c1x, c2x, rx], [c1y, c2y, ry]; pivot row 1 when |E10| >= |E00|
    swap = np.abs(c1[:, 1]) >= np.abs(c1[:, 0])
    a00 = np.where(swap, c1[:, 1], c1[:, 0])
    a01 = np.where(swap, c2[:, 1], c2[:, 0])
    a02 = np.where(swap, r[:, 1], r[:, 0])
    a10 = np.where(swap, c1[:, 0], c1[:, 1])
    a11 = np.where(swap, c2[:, 0], c2[:, 1])
    a12 = np.where(swap, r[:, 0], r[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = a10 / a00
        a11 = a11 - f * a01
        a12 = a12 - f * a02
        det = a00 * a11
        ok = (a00 != 0.0) & (a11 != 0.0) & ~np.isnan(det) & ~(np.abs(det) <= 1e-10 * scale)
        l1 = a12 / a11
        l0 = (a02 - a01 * l1) / a00
        w = np.stack([1.0 - (l0 + l1), l0, l1], axis=1)
        m = np.abs(w).max(axis=1)
    if select == "quad":  # the smallest bound of the error on quadratics
        d = cc[idx] - xf
        q = (np.abs(w) * (d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1])).sum(axis=1)
        cand = np.flatnonzero(ok & (m < MAX_WEIGHT))
        if len(cand) == 0:
            return None
        k = cand[np.argmin(q[cand])]
        return idx[k], w[k]
    good = np.flatnonzero(ok & (m < 1.0)) if select == "first" else []
    if len(good):
        k = good[0]
    else:
        cand = np.flatnonzero(ok & (m < MAX_WEIGHT))
        if len(cand) == 0:
            return None
        k = cand[np.argmin(m[cand])]
    return idx[k], w[k]


def bfs(nb, seeds, depth):
    seen = set(seeds)
    out = list(seeds)
    level = list(seeds)
    for _ in range(depth):
        nxt = []
        for c in level:
            for n in nb[c]:
                if n >= 0 and n not in seen:
                    seen.add(n)
                    nxt.append(n)
        out += nxt
        level = nxt
    return np.array(out, dtype=np.int64)


def reconstruction(face_cells, fc, cc, nb, order="distance", select="first", depth_in=1,
                   bselect="same"):
    """Facet stencils: (nf, 3) cells and weights. `order`: the pool sorted by the distance
    of the barycentres to the facet centroid (ties by id) and capped at MAX_POOL, or by
    cell id (`id`, no cap); `depth_in`: graph distance of the interior pool."""
    nf = len(face_cells)
    st_cells = np.empty((nf, 3), dtype=np.int64)
    st_w = np.empty((nf, 3))
    for f in range(nf):
        a, b = face_cells[f]
        seeds, depth = ([a, b], depth_in) if b >= 0 else ([a], 2)
        xf = fc[f]
        for extra in range(3):
            out = bfs(nb, seeds, depth + extra)
            d = cc[out] - xf
            d2 = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
            if order == "id":
                pool = np.sort(out)
                pool = pool[:MAX_POOL] if len(pool) <= MAX_POOL else out[np.lexsort((out, d2))][:MAX_POOL]
            else:
                pool = out[np.lexsort((out, d2))][:MAX_POOL]
            s = best_subset(pool, cc, xf, select if b >= 0 or bselect == "same" else bselect)
            if s is not None:
                st_cells[f], st_w[f] = s
                break
            if len(out) <= MAX_POOL and extra > 0 and len(out) == len(pool):
                s = None
                break
        if s is None:
            raise RuntimeError(f"no admissible stencil for facet {f} at {xf}")
    return st_cells, st_w


# ----------------------------------------------------------------------------- law
def law_matrix(lam, g, gc, mm):
    """A on s = (e11, e12, e21, e22, k1, k2) (strain_index(a, j) = 2a + j)."""
    A = np.zeros((6, 6))
    for i in range(2):
        for j in range(2):
            r = 2 * i + j
            A[r, r] += g + gc
            A[r, 2 * j + i] += g - gc
            if i == j:
                for k in range(2):
                    A[r, 3 * k] += lam
    A[4, 4] = A[5, 5] = mm
    return A


def block_diag_coo(blocks, size):
    """Sparse block diagonal matrix of the (n, size, size) blocks."""
    n = len(blocks)
    base = np.arange(n)[:, None, None] * size
    rows = np.broadcast_to(base + np.arange(size)[None, :, None], blocks.shape)
    cols = np.broadcast_to(base + np.arange(size)[None, None, :], blocks.shape)
    return sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n * size, n * size))


# ----------------------------------------------------------------------------- solver
def solve(pts, tri, r, rl, n_cos, opt=None):
    opt = dict(DEFAULTS, **(opt or {}))
    timer = {}
    t0 = time.perf_counter()
    nc = len(tri)
    a_ratio = n_cos * n_cos / (1.0 - n_cos * n_cos)
    length = r / rl
    lam = 2.0 * G * NU / (1.0 - 2.0 * NU)
    A = law_matrix(lam, G, a_ratio * G, 4.0 * G * length * length)

    # geometry
    face_nodes, face_cells, cell_faces = mesh_topology(pts, tri)
    nf = len(face_nodes)
    cc, vol, fc, area, normal = geometry(pts, tri, face_nodes, face_cells, cell_faces)
    tang = pts[face_nodes[:, 1]] - pts[face_nodes[:, 0]]
    P = pts[tri]
    diam = np.max(np.stack([_norm(P[:, i] - P[:, j])
                            for i, j in ((0, 1), (1, 2), (2, 0))]), axis=0)
    interior = face_cells[:, 1] >= 0
    nb = np.where(face_cells[cell_faces, 0] == np.arange(nc)[:, None],
                  face_cells[cell_faces, 1], face_cells[cell_faces, 0])

    # reconstruction (eqs. 8-10) and gradient operator (11)
    t_rec = time.perf_counter()
    st_cells, st_w = reconstruction(face_cells, fc, cc, nb, opt["order"], opt["select"], opt["depth"],
                                     opt["bselect"])
    Fint = sp.csr_matrix((st_w.ravel(), (np.repeat(np.arange(nf), 3), st_cells.ravel())), shape=(nf, nc))
    sign = np.where(face_cells[cell_faces, 0] == np.arange(nc)[:, None], 1.0, -1.0)  # (nc, 3)
    n_out = normal[cell_faces] * sign[..., None]                                       # (nc, 3, 2)
    s = area[cell_faces] / vol[:, None]                                               # (nc, 3)
    coef = (s[..., None] * st_w[cell_faces])[..., None] * n_out[:, :, None, :]       # (nc, 3, 3, 2)
    rows = np.broadcast_to(np.arange(nc)[:, None, None], st_cells[cell_faces].shape)
    Gx = sp.csr_matrix((coef[..., 0].ravel(), (rows.ravel(), st_cells[cell_faces].ravel())), shape=(nc, nc))
    Gy = sp.csr_matrix((coef[..., 1].ravel(), (rows.ravel(), st_cells[cell_faces].ravel())), shape=(nc, nc))
    timer["t_recon"] = time.perf_counter() - t_rec

    # strain operators B_q (6 nc x 3 nc), q = the facet midpoints of each cell
    def comp(M, a):  # scalar operator acting on component a of the 3 nc unknowns
        return sp.kron(M, sp.csr_matrix(([1.0], ([0], [a])), shape=(1, 3)), format="csr")

    def place(M, srow):  # scalar rows into strain row srow of each cell
        return sp.kron(M, sp.csr_matrix(([1.0], ([srow], [0])), shape=(6, 1)), format="csr")

    grad = sum(place(comp(Gd, a), 2 * a + j) for a in range(3) for j, Gd in enumerate((Gx, Gy)))
    Bs = []
    if opt["strain"] == "cell":  # the cell rotation, one point of weight |K|
        cell = sp.identity(nc, format="csr")
        Bs.append((grad + place(comp(cell, 2), 1) - place(comp(cell, 2), 2)).tocsr())
        Dq = block_diag_coo(np.broadcast_to(A, (nc, 6, 6)) * vol[:, None, None], 6)
    else:
        for i in range(3):
            Fi = Fint[cell_faces[:, i]]          # phi at the i-th facet midpoint of each cell
            rot = place(comp(Fi, 2), 1) - place(comp(Fi, 2), 2)   # e12 += phi, e21 -= phi
            Bs.append((grad + rot).tocsr())
        Dq = block_diag_coo(np.broadcast_to(A, (nc, 6, 6)) * (vol / 3.0)[:, None, None], 6)
    K = sum(B.T @ Dq @ B for B in Bs)

    # interior penalty (17)
    fi = np.flatnonzero(interior)
    km, kp = face_cells[fi, 0], face_cells[fi, 1]
    nI = normal[fi]
    Q = np.einsum("fj,ajbl,fl->fab", nI, A.reshape(3, 2, 3, 2), nI)
    h = {"mean": 0.5 * (diam[km] + diam[kp]), "max": np.maximum(diam[km], diam[kp]),
         "min": np.minimum(diam[km], diam[kp]), "facet": area[fi],
         "centres": _norm(cc[kp] - cc[km])}[opt["hf"]] / opt["eta"]
    half = tang[fi] * (0.5 / np.sqrt(3.0))
    ni = len(fi)
    Sm = sp.csr_matrix((np.ones(ni), (np.arange(ni), km)), shape=(ni, nc))
    Sp = sp.csr_matrix((np.ones(ni), (np.arange(ni), kp)), shape=(ni, nc))
    Gxm, Gym, Gxp, Gyp = Gx[km], Gy[km], Gx[kp], Gy[kp]
    for sgn in (-1.0, 1.0):
        x = fc[fi] + sgn * half
        dm, dp = x - cc[km], x - cc[kp]
        J = (Sm + sp.diags(dm[:, 0]) @ Gxm + sp.diags(dm[:, 1]) @ Gym
             - Sp - sp.diags(dp[:, 0]) @ Gxp - sp.diags(dp[:, 1]) @ Gyp)
        J3 = sp.kron(J, sp.identity(3), format="csr")
        W = block_diag_coo(Q * (0.5 * area[fi] / h)[:, None, None], 3)
        K = K + J3.T @ W @ J3

    # Nitsche (18)-(20) on the fixed components, traction on the top
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    tol = 1e-9 * (hi - lo).max()
    bnd = np.flatnonzero(~interior)
    on = lambda axis, plane: bnd[np.all(np.abs(pts[face_nodes[bnd], axis] - plane) <= tol, axis=1)]
    fixed = [(f, 0) for f in on(0, lo[0])] + [(f, 2) for f in on(0, lo[0])] \
        + [(f, 1) for f in on(1, lo[1])] + [(f, 2) for f in on(1, lo[1])]
    ff = np.array([f for f, _ in fixed])
    fk = np.array([k for _, k in fixed])
    nfix = len(ff)
    Bbar = sum(Bs) / len(Bs)
    AB = block_diag_coo(np.broadcast_to(A, (nc, 6, 6)), 6) @ Bbar
    c_of = face_cells[ff, 0]
    sel_rows = np.repeat(np.arange(nfix), 2)
    sel_cols = (c_of[:, None] * 6 + fk[:, None] * 2 + np.arange(2)[None, :]).ravel()
    sel_vals = (normal[ff] * area[ff][:, None]).ravel()
    T = sp.csr_matrix((sel_vals, (sel_rows, sel_cols)), shape=(nfix, 6 * nc)) @ AB
    L = sp.csr_matrix((st_w[ff].ravel(), (np.repeat(np.arange(nfix), 3), (st_cells[ff] * 3 + fk[:, None]).ravel())),
                      shape=(nfix, 3 * nc))
    K = (K - L.T @ T + T.T @ L).tocsc()
    top = on(1, hi[1])
    rhs = np.zeros(3 * nc)
    if opt["traction"] == "cell":
        np.add.at(rhs, face_cells[top, 0] * 3 + 1, area[top])
    else:
        np.add.at(rhs, st_cells[top] * 3 + 1, st_w[top] * area[top][:, None])
    timer["t_assemble"] = time.perf_counter() - t0

    t1 = time.perf_counter()
    w = spsolve(K, rhs)
    timer["t_solve"] = time.perf_counter() - t1
    if not np.all(np.isfinite(w)):
        raise RuntimeError("non-finite solution")
    sig = (AB @ w).reshape(nc, 6)
    out = {"cells": nc, "dofs": 3 * nc, "nnz": int(K.nnz), "scf": float(sig[:, 3].max()),
           "max_weight": float(np.abs(st_w).max())}
    out.update(timer)
    return out


def hole_scf(nu, n, r, length):
    """Mindlin / Kaloni-Ariman SCF (crates/cosserat/src/reference.rs)."""
    from scipy.special import k0, k1
    if n == 0.0:
        return 3.0
    c = length / n
    x = r / c
    F = 8.0 * (1.0 - nu) * n * n / (4.0 + x * x + 2.0 * x * k0(x) / k1(x))
    return (3.0 + F) / (1.0 + F)


def main():
    import argparse
    p = argparse.ArgumentParser(description="variational Cosserat DEM, plate with a hole")
    p.add_argument("mesh")
    p.add_argument("r", type=float)
    p.add_argument("r_over_l", type=float)
    p.add_argument("n", type=float)
    p.add_argument("--order", choices=["distance", "id"], default=DEFAULTS["order"],
                   help="pool order: distance to the facet centroid, or cell id")
    p.add_argument("--select", choices=["first", "minmax", "quad"], default=DEFAULTS["select"],
                   help="first subset with max|lambda| < 1, or the smallest max|lambda|")
    p.add_argument("--bselect", choices=["same", "first", "minmax", "quad"], default=DEFAULTS["bselect"],
                   help="selection rule on boundary facets (same: as --select)")
    p.add_argument("--depth", type=int, choices=[1, 2], default=DEFAULTS["depth"],
                   help="graph distance of the interior-facet pool")
    p.add_argument("--strain", choices=["facet", "cell"], default=DEFAULTS["strain"],
                   help="rotation in the strain: facet (CR) values or the cell value")
    p.add_argument("--eta", type=float, default=DEFAULTS["eta"], help="interior penalty weight")
    p.add_argument("--hf", choices=["mean", "max", "min", "facet", "centres"], default=DEFAULTS["hf"],
                   help="h_F of the penalty: mean/max/min cell diameter, facet length, centre distance")
    p.add_argument("--traction", choices=["facet", "cell"], default=DEFAULTS["traction"],
                   help="traction tested with the facet values or the cell value")
    a = p.parse_args()
    if not (a.r > 0 and a.r_over_l > 0 and 0 <= a.n < 1 and a.eta > 0):
        sys.exit(f"need R > 0, R_OVER_L > 0, 0 <= N < 1 and eta > 0, got {a.r}, {a.r_over_l}, {a.n}, {a.eta}")
    opt = {k: getattr(a, k) for k in DEFAULTS}
    t = time.perf_counter()
    pts, tri = read_triangles(a.mesh)
    t_read = time.perf_counter() - t
    res = {"code": "python-dem", "mesh": a.mesh, "options": opt}
    res.update(solve(pts, tri, a.r, a.r_over_l, a.n, opt))
    res["t_read"] = t_read
    res["scf_ref"] = hole_scf(NU, a.n, a.r, a.r / a.r_over_l)
    res["peak_memory_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print("RESULT " + json.dumps(res), flush=True)


if __name__ == "__main__":
    main()
