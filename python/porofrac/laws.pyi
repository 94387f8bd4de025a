"""Type stubs of porofrac.laws: local stiffness matrices of the cell laws (see
docs/python.md). ``points`` (n, dim) in m, ``E`` in Pa; matrices (dim·n, dim·n) in N/m,
in the order of ``points``, ``dim`` rows per node; 2D is plane strain unless
``plane_stress``."""

from typing import Optional, Sequence

import numpy as np
import numpy.typing as npt

def vem_stiffness(
    points: npt.ArrayLike,
    cell: Optional[Sequence] = None,
    *,
    E: float,
    nu: float,
    plane_stress: bool = False,
) -> npt.NDArray[np.float64]:
    """First-order VEM stiffness (MRST vemmech stabilization). 2D: ``cell`` the polygon's
    node indices counter-clockwise (default: the points in order); 3D: ``cell`` the
    faces, outward loops of node indices (required)."""

def mdem_stiffness(
    points: npt.ArrayLike, *, E: float, nu: float, plane_stress: bool = False
) -> npt.NDArray[np.float64]:
    """MDEM stiffness of a simplex (3 points in 2D, 4 in 3D; any order)."""

def dem_stiffness(
    points: npt.ArrayLike, *, E: float, nu: float, plane_stress: bool = False
) -> npt.NDArray[np.float64]:
    """Central-force DEM stiffness of a simplex, every edge spring acting."""
