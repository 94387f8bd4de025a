"""Type stubs of the porofrac Python package (see docs/python.md)."""

import os
from typing import Any, Callable, Dict, List, Optional, Union

import numpy as np
import numpy.typing as npt

from . import grid as grid, laws as laws

__version__: str

PathLike = Union[str, os.PathLike[str]]
Progress = Union[bool, Callable[[int, int, float], Any], None]

def retain_freed_memory() -> bool:
    """Keep freed heap memory in this process for reuse, as the ``porofrac`` command
    does (faster solves; the resident size stays at its peak). Process-wide, not undone;
    whether it was applied (Linux with glibc)."""

class SceneError(ValueError):
    """A problem in a scene, as the `porofrac` command reports it."""

    key: Optional[str]
    """The dotted key the error names (``material.rock.poisson_ratio``), or None."""
    file: str
    """The scene file."""
    line: int
    """1-based line in the file; 0 when not at a line (a key set with ``Scene.set``)."""
    message: str
    """The message after ``file:line:``."""

class RunError(RuntimeError):
    """A run that failed; ``result`` holds what it computed before, when anything."""

    result: Optional["Result"]

class Scene:
    """A porofrac scene: a TOML scene file, the keys changed on it, and what runs it."""

    @classmethod
    def load(cls, path: PathLike) -> "Scene":
        """Read and validate the scene file ``path``; raises SceneError."""
    @classmethod
    def from_toml(cls, text: str, path: Optional[PathLike] = None) -> "Scene":
        """A scene from TOML text; ``path`` names it in errors, anchors relative paths."""
    @classmethod
    def from_dict(cls, d: Dict[str, Any], path: Optional[PathLike] = None) -> "Scene":
        """A scene from a dict of its tables (as ``tomllib`` reads a scene file)."""
    def set(self, key: str, value: Any) -> "Scene":
        """Set the dotted ``key`` to ``value`` (SI units), as ``--set KEY=VALUE``."""
    def copy(self) -> "Scene":
        """An independent copy."""
    @property
    def path(self) -> str:
        """The scene file's path."""
    @property
    def overrides(self) -> Dict[str, str]:
        """The keys set so far, values as TOML text."""
    def to_toml(self) -> str:
        """The scene as TOML with the keys set applied."""
    def to_dict(self) -> Dict[str, Any]:
        """The scene's tables with the keys set applied."""
    def check(self) -> Dict[str, Any]:
        """Validate and build as a run would, writing nothing; what a run would do."""
    def run(
        self, out: Optional[PathLike] = None, progress: Progress = True, fields: bool = True
    ) -> "Result":
        """Run the scene (in memory when ``out`` is None); GIL released while stepping;
        ``fields=False`` keeps probes, lines and summary only."""

class Grid:
    """The grid of a run in VTK terms."""

    dim: int
    points: npt.NDArray[np.float64]
    """(n, 3) node coordinates, m."""
    connectivity: npt.NDArray[np.int64]
    offsets: npt.NDArray[np.int64]
    cell_types: npt.NDArray[np.uint8]
    faces: npt.NDArray[np.int64]
    face_offsets: npt.NDArray[np.int64]
    tags: Dict[str, npt.NDArray[np.int64]]
    volumes: Optional[npt.NDArray[np.float64]]
    """(n_cells,) cell volumes, m³ (areas in 2D, m²); grids of :mod:`porofrac.grid` only."""
    centroids: Optional[npt.NDArray[np.float64]]
    """(n_cells, dim) cell centroids, m; grids of :mod:`porofrac.grid` only."""
    @property
    def num_cells(self) -> int: ...
    def cells(self) -> List[npt.NDArray[np.int64]]:
        """The node list of every cell."""

class Result:
    """What a run computed (arrays hold the buffers the run filled; nothing copied)."""

    @property
    def summary(self) -> Dict[str, Any]:
        """``summary.json`` as a dict."""
    @property
    def out(self) -> Optional[str]:
        """The output folder, or None for a run kept in memory."""
    @property
    def probes(self) -> Dict[str, npt.NDArray[np.float64]]:
        """Probe name → values at the sampled times; ``"time"``: the times (s)."""
    @property
    def units(self) -> Dict[str, str]:
        """Probe name → unit."""
    @property
    def lines(self) -> Dict[str, npt.NDArray[np.float64]]:
        """Line name → rows ``time, s, x, y(, z), value`` of every written step."""
    def line_columns(self, name: str) -> List[str]: ...
    def line(self, name: str, step: int = -1) -> npt.NDArray[np.float64]:
        """Rows ``s, x, y(, z), value`` of line ``name`` at written step ``step``."""
    @property
    def times(self) -> npt.NDArray[np.float64]:
        """The written times (s)."""
    @property
    def grid(self) -> Optional[Grid]:
        """The grid (continuum, cosserat), or None."""
    def field_names(self, step: int = -1) -> List[str]: ...
    def field(self, name: str, step: int = -1) -> npt.NDArray[np.float64]:
        """Grid field ``name`` at written step ``step`` (point or cell field)."""
    def particles(self, step: int = -1) -> Dict[str, npt.NDArray[np.float64]]:
        """Disk positions, radii, velocities, links and forces at ``step``."""
    def lattice(self, step: int = -1) -> Dict[str, Any]:
        """Lattice ``vx``, ``vy``, ``pressure``, ``density``, ``solid``, ``temperature``
        as (ny, nx) arrays; ``origin``, ``spacing``."""
    def probes_frame(self) -> Any:
        """The probes as a pandas DataFrame indexed by time."""
    def to_meshio(self, step: int = -1) -> Any:
        """A ``meshio.Mesh`` of the grid and fields at ``step``."""
    def to_pyvista(self, step: int = -1) -> Any:
        """A ``pyvista.UnstructuredGrid`` of the grid and fields at ``step``."""
