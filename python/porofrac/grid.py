"""Grids without a scene: read from the files a ``[grid] kind = "file"`` scene reads, or
generated as the ``[grid]`` kinds generate them.

Every function returns a :class:`porofrac.Grid` with ``points`` (n, 3) node coordinates
(m; z = 0 in 2D), ``connectivity``/``offsets`` the nodes of every cell (counter-clockwise
polygons in 2D), ``cell_types`` (VTK types), ``faces``/``face_offsets`` (3D polyhedra's
face streams), ``tags`` (cell tag name → cell indices), ``volumes`` (cell volumes, m³;
areas in 2D, m²) and ``centroids`` (n_cells, dim), m. The grid is validated as a run
validates it (closed cells, positive volumes); a bad file or bad sizes raise
``ValueError`` naming the argument or the file (and its line where the reader knows it).

    >>> import porofrac
    >>> g = porofrac.grid.cartesian([0, 0], [1, 1], [4, 2])
    >>> g.num_cells, g.volumes.sum()
    (8, 1.0)
"""

from __future__ import annotations

import os
from typing import Sequence, Union

from . import Grid
from ._porofrac import grid_box, grid_read, grid_voronoi

__all__ = ["read", "cartesian", "triangles", "tetrahedra", "voronoi"]


def read(path: Union[str, os.PathLike], dim: Union[int, None] = None) -> Grid:
    """Read a grid file: a Gmsh ``.msh`` or VTK ``.vtu`` mesh (``dim`` 2 or 3, as the
    scene's ``scene.dim``), or a corner-point deck (``.grdecl``/``.data``; 3D, ``dim``
    may be left out). Tags are the mesh's physical groups (Gmsh) or cell tags."""
    return Grid(grid_read(os.fspath(path), dim))


def cartesian(lo: Sequence[float], hi: Sequence[float], cells: Sequence[int]) -> Grid:
    """Squares (2D) or cubes (3D) on the box ``[lo, hi]`` (m), ``cells`` per axis; cells
    and nodes numbered x fastest (``[grid] kind = "cartesian"``)."""
    return Grid(grid_box("cartesian", _floats(lo), _floats(hi), _counts(cells)))


def triangles(lo: Sequence[float], hi: Sequence[float], cells: Sequence[int]) -> Grid:
    """Each square of a 2D Cartesian grid split into two triangles
    (``[grid] kind = "triangles"``)."""
    _need_dim(cells, 2, "triangles")
    return Grid(grid_box("simplices", _floats(lo), _floats(hi), _counts(cells)))


def tetrahedra(lo: Sequence[float], hi: Sequence[float], cells: Sequence[int]) -> Grid:
    """Each cube of a 3D Cartesian grid split into tetrahedra
    (``[grid] kind = "tetrahedra"``)."""
    _need_dim(cells, 3, "tetrahedra")
    return Grid(grid_box("simplices", _floats(lo), _floats(hi), _counts(cells)))


def voronoi(
    lo: Sequence[float], hi: Sequence[float], cells: int, seed: int = 0, lloyd: int = 3
) -> Grid:
    """A 2D centroidal Voronoi grid of ``cells`` cells on ``[lo, hi]`` (m): random
    generators from ``seed``, then ``lloyd`` Lloyd iterations (``[grid] kind =
    "voronoi"``; the same seed gives the same grid)."""
    if isinstance(cells, bool) or not isinstance(cells, int) or cells < 1:
        raise ValueError(f"cells = {cells!r}: need a positive number of cells")
    if lloyd < 0 or seed < 0:
        raise ValueError(f"seed = {seed}, lloyd = {lloyd}: need non-negative integers")
    return Grid(grid_voronoi(_floats(lo), _floats(hi), cells, seed, lloyd))


def _floats(v: Sequence[float]) -> list:
    return [float(x) for x in v]


def _counts(cells: Sequence[int]) -> list:
    out = []
    for n in cells:
        if isinstance(n, bool) or int(n) != n or n < 1:
            raise ValueError(f"cells = {list(cells)!r}: need positive integers, one per axis")
        out.append(int(n))
    return out


def _need_dim(cells: Sequence[int], dim: int, what: str) -> None:
    if len(cells) != dim:
        raise ValueError(f"cells = {list(cells)!r}: {what} need {dim} counts (one per axis)")
