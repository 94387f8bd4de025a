"""Plane-strain Cosserat plate with a hole with FEniCSx: mixed P2 displacement - P1
micro-rotation on the same triangle mesh as porofrac (seed 001.4 E2).

usage: python fenicsx_p2p1.py MESH.vtu R R_OVER_L N

Same problem as crates/cosserat/examples/plate_hole.rs and peers/cosserat/dem.py: quarter
plate 16.2 mm with a hole of radius R (mm), G = 1000 MPa, nu = 0.3, Gc = G N^2/(1 - N^2),
l = R / R_OVER_L, so lambda = 2 G nu/(1 - 2 nu), m = 4 G l^2 grad(phi);
e = grad(u) + phi J (e12 = d2 u1 + phi, e21 = d1 u2 - phi),
sigma = lambda tr(e) I + (G + Gc) e + (G - Gc) e^T.
BCs: u1 = phi = 0 on x = 0, u2 = phi = 0 on y = 0 (strong), traction (0, 1) on y = 16.2,
hole and right edge free. Linear solve: MUMPS LU through PETSc.

SCF = the largest value of the finite-element sigma_22: sigma is affine in each cell (grad of
P2 and P1 phi), so it is interpolated exactly into discontinuous P1 and the maximum is taken
over those nodal values (cell corners); the maximum sits at the hole's point (R, 0).

Prints one line RESULT {json} with cells, dofs, nnz, scf, t_assemble (matrix and vector
assembly with the BCs, forms compiled beforehand), t_solve (MUMPS factorisation + solve).
"""
import json
import sys
import time

import basix.ufl
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx
from dolfinx import fem, mesh
from dolfinx.fem.petsc import apply_lifting, assemble_matrix, assemble_vector, set_bc

from dem import hole_scf
from vtu import read_triangles

SIDE, G, NU = 16.2, 1e3, 0.3


def main():
    if len(sys.argv) != 5:
        sys.exit("usage: python fenicsx_p2p1.py MESH.vtu R R_OVER_L N")
    path, r, rl, n_cos = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    if not (r > 0 and rl > 0 and 0 <= n_cos < 1):
        sys.exit(f"need R > 0, R_OVER_L > 0 and 0 <= N < 1, got {r}, {rl}, {n_cos}")
    comm = MPI.COMM_WORLD
    pts, tri = read_triangles(path)
    coord = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))
    msh = mesh.create_mesh(comm, tri, coord, pts)
    gc = G * n_cos * n_cos / (1.0 - n_cos * n_cos)
    length = r / rl
    lam = 2.0 * G * NU / (1.0 - 2.0 * NU)

    P2 = basix.ufl.element("Lagrange", "triangle", 2, shape=(2,))
    P1 = basix.ufl.element("Lagrange", "triangle", 1)
    W = fem.functionspace(msh, basix.ufl.mixed_element([P2, P1]))
    (u, phi), (v, psi) = ufl.TrialFunctions(W), ufl.TestFunctions(W)
    J = ufl.as_matrix([[0.0, 1.0], [-1.0, 0.0]])

    def strain(w, p):
        return ufl.grad(w) + p * J

    def stress(e):
        return lam * ufl.tr(e) * ufl.Identity(2) + (G + gc) * e + (G - gc) * e.T

    mm = 4.0 * G * length * length
    a = fem.form(ufl.inner(stress(strain(u, phi)), strain(v, psi)) * ufl.dx
                 + mm * ufl.inner(ufl.grad(phi), ufl.grad(psi)) * ufl.dx)
    tdim = 2
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    tol = 1e-9 * (hi - lo).max()
    top = mesh.locate_entities_boundary(msh, tdim - 1, lambda x: np.abs(x[1] - hi[1]) <= tol)
    tags = mesh.meshtags(msh, tdim - 1, top, np.full(len(top), 1, dtype=np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    L = fem.form(ufl.inner(fem.Constant(msh, PETSc.ScalarType((0.0, 1.0))), v) * ds(1))

    # sigma_22 as a discontinuous P1 field (exact for this discretisation)
    wh = fem.Function(W)
    uh, phih = wh.split()
    S = fem.functionspace(msh, ("Discontinuous Lagrange", 1))
    s22 = fem.Function(S)
    s22_expr = fem.Expression(stress(strain(uh, phih))[1, 1], S.element.interpolation_points)

    comm.Barrier()
    t0 = time.perf_counter()
    left = mesh.locate_entities_boundary(msh, tdim - 1, lambda x: np.abs(x[0] - lo[0]) <= tol)
    bottom = mesh.locate_entities_boundary(msh, tdim - 1, lambda x: np.abs(x[1] - lo[1]) <= tol)
    bcs = []
    for facets, comps in ((left, [(0, 0), (1, None)]), (bottom, [(0, 1), (1, None)])):
        for sub, k in comps:
            Vs = W.sub(sub) if k is None else W.sub(sub).sub(k)
            dofs = fem.locate_dofs_topological(Vs, tdim - 1, facets)
            bcs.append(fem.dirichletbc(PETSc.ScalarType(0.0), dofs, Vs))
    A = assemble_matrix(a, bcs=bcs)
    A.assemble()
    b = assemble_vector(L)
    apply_lifting(b, [a], bcs=[bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    set_bc(b, bcs)
    t_assemble = time.perf_counter() - t0

    t1 = time.perf_counter()
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setUp()
    ksp.solve(b, wh.x.petsc_vec)
    wh.x.scatter_forward()
    t_solve = time.perf_counter() - t1

    s22.interpolate(s22_expr)
    scf = float(s22.x.array.max())
    info = A.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)
    res = {"code": "fenicsx-p2p1", "mesh": path, "cells": int(msh.topology.index_map(2).size_global),
           "dofs": int(W.dofmap.index_map.size_global * W.dofmap.index_map_bs), "nnz": int(info["nz_used"]),
           "scf": scf, "scf_ref": hole_scf(NU, n_cos, r, length),
           "t_assemble": t_assemble, "t_solve": t_solve,
           "version": f"dolfinx {dolfinx.__version__}, PETSc {'.'.join(map(str, PETSc.Sys.getVersion()))}"}
    if comm.rank == 0:
        print("RESULT " + json.dumps(res), flush=True)


if __name__ == "__main__":
    main()
