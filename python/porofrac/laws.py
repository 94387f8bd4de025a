"""Local stiffness matrices of porofrac's cell laws as numpy arrays, for checking a law or
building one's own assembly.

Every function takes the cell's node coordinates ``points`` (n, dim), m, and an
isotropic material: Young's modulus ``E`` (Pa) and Poisson's ratio ``nu``; 2D is plane
strain unless ``plane_stress=True``. It returns the stiffness ``K`` (N/m), shape
``(dim·n, dim·n)``, rows and columns in the order of ``points``, ``dim`` per node
(``[u0x, u0y, u1x, u1y, ...]``): the nodal forces of displacements ``u`` are ``-K @ u``
and the cell's elastic energy is ``u @ K @ u / 2`` (J; J/m in 2D). A cell the law
cannot evaluate (too few nodes, degenerate, inverted, wrong shapes) raises
``ValueError``.

    >>> import numpy as np, porofrac
    >>> K = porofrac.laws.vem_stiffness([[0, 0], [1, 0], [1, 1], [0, 1]], E=1.0, nu=0.3)
    >>> K.shape
    (8, 8)
"""

from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

from ._porofrac import simplex_stiffness, vem_stiffness as _vem_stiffness

__all__ = ["vem_stiffness", "mdem_stiffness", "dem_stiffness"]


def vem_stiffness(
    points,
    cell: Optional[Sequence] = None,
    *,
    E: float,
    nu: float,
    plane_stress: bool = False,
) -> np.ndarray:
    """The first-order VEM stiffness of one cell, with the stabilization of MRST's
    vemmech (the default of a scene's ``law = "vem"``).

    2D: ``cell`` is the polygon, node indices counter-clockwise (default: the points in
    order). 3D: ``cell`` is the list of faces, each a loop of node indices oriented
    outward (required)."""
    p = _points(points)
    if cell is None:
        c = None
    elif p.shape[1] == 2:
        c = [[_index(i) for i in cell]]
    else:
        c = [[_index(i) for i in face] for face in cell]
    return _vem_stiffness(p, c, float(E), float(nu), bool(plane_stress))


def mdem_stiffness(points, *, E: float, nu: float, plane_stress: bool = False) -> np.ndarray:
    """The MDEM stiffness of a simplex (3 points in 2D, 4 in 3D; any order): the edge
    springs that reproduce linear elasticity, ``K = |K| (M⁻¹)ᵀ D M⁻¹`` in edge terms
    (equal to the VEM and P1 stiffness on the same simplex)."""
    return simplex_stiffness(_points(points), float(E), float(nu), bool(plane_stress), False)


def dem_stiffness(points, *, E: float, nu: float, plane_stress: bool = False) -> np.ndarray:
    """The central-force DEM stiffness of a simplex with every edge acting (an intact or
    all-closed fractured cell): the diagonal of the MDEM edge stiffness, one spring per
    edge along it."""
    return simplex_stiffness(_points(points), float(E), float(nu), bool(plane_stress), True)


def _points(points) -> np.ndarray:
    p = np.ascontiguousarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"points: need shape (n, 2) or (n, 3), got {p.shape}")
    return p


def _index(i) -> int:
    if isinstance(i, bool) or int(i) != i or i < 0:
        raise ValueError(f"cell: node index {i!r} is not a non-negative integer")
    return int(i)
