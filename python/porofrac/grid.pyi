"""Type stubs of porofrac.grid: grids without a scene (see docs/python.md)."""

import os
from typing import Optional, Sequence, Union

from . import Grid

def read(path: Union[str, os.PathLike[str]], dim: Optional[int] = None) -> Grid:
    """A Gmsh ``.msh`` / VTK ``.vtu`` mesh (``dim`` 2 or 3) or a corner-point deck
    (``.grdecl``/``.data``, 3D), validated as a run validates it."""

def cartesian(lo: Sequence[float], hi: Sequence[float], cells: Sequence[int]) -> Grid:
    """Squares/cubes on the box ``[lo, hi]`` (m), ``cells`` per axis (2 or 3 axes)."""

def triangles(lo: Sequence[float], hi: Sequence[float], cells: Sequence[int]) -> Grid:
    """2D: each square of the Cartesian grid split into two triangles."""

def tetrahedra(lo: Sequence[float], hi: Sequence[float], cells: Sequence[int]) -> Grid:
    """3D: each cube of the Cartesian grid split into tetrahedra."""

def voronoi(
    lo: Sequence[float], hi: Sequence[float], cells: int, seed: int = 0, lloyd: int = 3
) -> Grid:
    """2D centroidal Voronoi grid of ``cells`` cells on ``[lo, hi]`` (m)."""
