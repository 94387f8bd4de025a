"""porofrac from Python: scenes, parameter studies and results as numpy arrays.

A scene is read from a TOML file (:meth:`Scene.load`), text (:meth:`Scene.from_toml`) or a
dict (:meth:`Scene.from_dict`), changed with the file's dotted keys (:meth:`Scene.set`,
as ``porofrac run --set`` does), checked (:meth:`Scene.check`) and run
(:meth:`Scene.run`). A run releases the GIL while it steps, keeps its results in memory
(``out=None``; nothing is written) or writes the files of ``porofrac run`` into ``out``,
and returns a :class:`Result` whose arrays are numpy arrays holding the buffers the run
filled (no copy).

    >>> import porofrac
    >>> scene = porofrac.Scene.load("scenes/hydrofrac_seed.toml")
    >>> scene.set("material.rock.youngs_modulus", 2e10)
    >>> result = scene.run()
    >>> result.probes["p_well"].max()          # Pa

All numbers are SI (m, s, Pa, kg); ``Result.units`` names the unit of every probe.
Errors: :class:`SceneError` (a problem in the scene: ``key``, ``file``, ``line``, the
message ``porofrac`` prints) and :class:`RunError` (a run that failed).
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Optional, Union

import numpy as np

from ._porofrac import RunError, SceneError, _Result, _Scene, __version__, retain_freed_memory

__all__ = [
    "grid",
    "laws",
    "Scene",
    "Result",
    "Grid",
    "SceneError",
    "RunError",
    "retain_freed_memory",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]
Progress = Union[bool, Callable[[int, int, float], Any], None]


class Scene:
    """A porofrac scene: a TOML scene file, the keys changed on it, and what runs it.

    Make one with :meth:`load`, :meth:`from_toml` or :meth:`from_dict`. Keys are the
    scene file's dotted keys (``"material.rock.youngs_modulus"``; ``"bc.2.value"`` is
    ``value`` in the second ``[[bc]]``), values in SI units; docs/SCENE.md lists them all.
    """

    __slots__ = ("_inner",)

    def __init__(self, inner: _Scene) -> None:
        self._inner = inner

    @classmethod
    def load(cls, path: PathLike) -> "Scene":
        """Read and validate the scene file ``path``; raises :class:`SceneError`."""
        return cls(_Scene.load(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, path: Optional[PathLike] = None) -> "Scene":
        """A scene from TOML text. ``path`` names it in errors and anchors relative paths
        (mesh files); default ``<scene>.toml`` in the current directory."""
        return cls(_Scene.from_toml(text, None if path is None else os.fspath(path)))

    @classmethod
    def from_dict(cls, d: Dict[str, Any], path: Optional[PathLike] = None) -> "Scene":
        """A scene from a dict of its tables, as ``tomllib.load`` returns for a scene
        file (``{"scene": {"name": "x", "dim": 2}, "grid": {...}, ...}``)."""
        return cls.from_toml(_Scene.dict_to_toml(d), path)

    def set(self, key: str, value: Any) -> "Scene":
        """Set the dotted ``key`` to ``value`` (bool, int, float, str, list or dict), as
        ``porofrac run --set KEY=VALUE`` does: checked when the scene is checked or run,
        an error naming ``--set KEY``. Returns the scene, so calls chain."""
        self._inner.set(key, value)
        return self

    def copy(self) -> "Scene":
        """An independent copy (for a parameter study)."""
        import copy

        return Scene(copy.copy(self._inner))

    @property
    def path(self) -> str:
        """The scene file's path (or the name given to text)."""
        return os.fspath(self._inner.path())

    @property
    def overrides(self) -> Dict[str, str]:
        """The keys set so far, with their values as TOML text."""
        return dict(self._inner.overrides())

    def to_toml(self) -> str:
        """The scene as TOML with the keys set applied (comments are not kept)."""
        return self._inner.to_toml()

    def to_dict(self) -> Dict[str, Any]:
        """The scene's tables as a dict, with the keys set applied."""
        return json.loads(self._inner.to_json())

    def check(self) -> Dict[str, Any]:
        """Validate the scene and build its model as a run would, writing nothing.

        Returns what a run would do: ``counts`` (cells, nodes, unknowns, particles...),
        ``steps``, ``written``, ``peak_bytes`` (estimated peak memory, bytes) and
        ``text`` (the lines ``porofrac check`` prints). Raises :class:`SceneError` with
        the message, key, file and line of ``porofrac check``.
        """
        return self._inner.check()

    def run(
        self, out: Optional[PathLike] = None, progress: Progress = True, fields: bool = True
    ) -> "Result":
        """Run the scene.

        ``out=None`` keeps the results in memory and writes nothing; a folder writes the
        files of ``porofrac run`` there too. ``progress``: ``True`` shows a tqdm bar when
        tqdm is installed (nothing otherwise), ``False`` nothing, or a callable
        ``progress(step, total, time)`` called after every step (``time`` in s).
        ``fields=False`` keeps the probes, lines and summary only, not the state of the
        written steps (grid, fields, particles, lattice): less memory and time for big
        grids.

        The GIL is released while the model steps, so other Python threads keep running.
        Ctrl-C stops the run after the step in progress and raises ``KeyboardInterrupt``
        whose ``result`` attribute holds the partial :class:`Result`. A failed run raises
        :class:`RunError` (or :class:`SceneError` for a problem in the scene).
        """
        callback, close = _progress(progress, self._inner.path())
        try:
            inner = self._inner.run(None if out is None else os.fspath(out), callback, fields)
        except KeyboardInterrupt as e:
            partial = getattr(e, "result", None)
            if partial is not None:
                e.result = Result(partial)
            raise
        except RunError as e:
            partial = getattr(e, "result", None)
            if partial is not None:
                e.result = Result(partial)
            raise
        finally:
            close()
        return Result(inner)

    def __repr__(self) -> str:
        extra = f", {len(self.overrides)} keys set" if self.overrides else ""
        return f"Scene({self.path!r}{extra})"


def _progress(progress: Progress, path: str):
    """The callback for ``progress`` and what closes it."""
    if progress is None or progress is False:
        return None, lambda: None
    if callable(progress) and progress is not True:
        return progress, lambda: None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None, lambda: None
    bar = tqdm(desc=os.path.basename(os.fspath(path)), unit="step")

    def callback(step: int, total: int, time: float) -> None:
        if bar.total != total:
            bar.total = total
        bar.n = step + 1
        bar.set_postfix_str(f"t = {time:.4g} s", refresh=False)
        bar.refresh()

    return callback, bar.close


class Grid:
    """The grid of a run in VTK terms (numpy arrays).

    ``points`` (n, 3) node coordinates (m; z = 0 in 2D); ``connectivity`` the nodes of
    every cell, cell after cell, ending at ``offsets``; ``cell_types`` VTK types
    (5 triangle, 9 quad, 7 polygon, 10 tetra, 42 polyhedron); ``faces`` /
    ``face_offsets`` the polyhedra's face streams (3D); ``tags`` cell tag name →
    cell indices. Grids from :mod:`porofrac.grid` also have ``volumes`` (n_cells,)
    cell volumes (m³; areas in 2D, m²) and ``centroids`` (n_cells, dim) cell centroids
    (m); a run's grid has None there.
    """

    def __init__(self, d: Dict[str, Any]) -> None:
        self.dim: int = d["dim"]
        self.points: np.ndarray = d["points"]
        self.connectivity: np.ndarray = d["connectivity"]
        self.offsets: np.ndarray = d["offsets"]
        self.cell_types: np.ndarray = d["cell_types"]
        self.faces: np.ndarray = d["faces"]
        self.face_offsets: np.ndarray = d["face_offsets"]
        self.tags: Dict[str, np.ndarray] = d["tags"]
        self.volumes: Optional[np.ndarray] = d.get("volumes")
        self.centroids: Optional[np.ndarray] = d.get("centroids")

    @property
    def num_cells(self) -> int:
        """Number of cells."""
        return len(self.offsets)

    def cells(self):
        """The node list of every cell (a list of 1-D arrays)."""
        starts = np.concatenate(([0], self.offsets[:-1]))
        return [self.connectivity[a:b] for a, b in zip(starts, self.offsets)]

    def __repr__(self) -> str:
        return f"Grid({self.dim}D, {len(self.points)} points, {self.num_cells} cells)"


class Result:
    """What a run computed.

    ``summary`` (the content of ``summary.json``), ``probes`` (name → 1-D array;
    ``probes["time"]`` the sampled times, s), ``units`` (probe → unit), ``lines`` (name →
    2-D array with the columns of ``lines/<name>.csv``), ``times`` (the written times,
    s), :meth:`field` (a grid field at a written step), ``grid``, :meth:`particles` and
    :meth:`lattice`. Field arrays hold the buffers the run filled: nothing is copied.
    """

    def __init__(self, inner: _Result) -> None:
        self._inner = inner
        self._summary = None

    @property
    def summary(self) -> Dict[str, Any]:
        """The run's ``summary.json`` as a dict (status, sizes, wall times, extrema...);
        ``{}`` for a run that failed."""
        if self._summary is None:
            text = self._inner.summary_json
            self._summary = json.loads(text) if text else {}
        return self._summary

    @property
    def out(self) -> Optional[str]:
        """The output folder, or None for a run kept in memory."""
        o = self._inner.out
        return None if o is None else os.fspath(o)

    @property
    def probes(self) -> Dict[str, np.ndarray]:
        """Probe name → values at the sampled times (``"time"``: the times, s)."""
        return self._inner.probes

    @property
    def units(self) -> Dict[str, str]:
        """Probe name → unit (``"Pa"``, ``"m"``; ``"1"`` for plain numbers)."""
        return self._inner.units

    @property
    def lines(self) -> Dict[str, np.ndarray]:
        """Line name → rows ``time, s, x, y(, z), value`` of every written step, as in
        ``lines/<name>.csv`` (see :meth:`line_columns`)."""
        return {k: v["rows"] for k, v in self._inner.lines.items()}

    def line_columns(self, name: str):
        """The column names of line ``name``."""
        return list(self._inner.lines[name]["columns"])

    def line(self, name: str, step: int = -1) -> np.ndarray:
        """The rows ``s, x, y(, z), value`` of line ``name`` at written step ``step``."""
        rows = self.lines[name]
        t = self.times[step]
        return rows[rows[:, 0] == t][:, 1:]

    @property
    def times(self) -> np.ndarray:
        """The written times (s): the steps :meth:`field` and :meth:`particles` index."""
        return self._inner.times

    @property
    def grid(self) -> Optional[Grid]:
        """The grid (grid models: continuum, cosserat), or None."""
        g = self._inner.grid
        return None if g is None else Grid(g)

    def _step(self, step: int) -> Dict[str, Any]:
        steps = self._inner.steps
        if not steps:
            raise ValueError("this run kept no state (a failed run, or none written)")
        return steps[step]

    def field_names(self, step: int = -1):
        """The names of the grid fields at written step ``step``."""
        s = self._step(step)
        return sorted(set(s["point"]) | set(s["cell"]))

    def field(self, name: str, step: int = -1) -> np.ndarray:
        """Grid field ``name`` at written step ``step`` (default: the last): a point
        field (``displacement``, one row per node) or a cell field (``stress`` as
        ``xx, yy, zz, xy, yz, xz`` in Pa, ``pressure``, ``fractured``...)."""
        s = self._step(step)
        for where in ("point", "cell"):
            if name in s[where]:
                return s[where][name]
        raise KeyError(f"no field {name!r}; the fields are {self.field_names(step)}")

    def particles(self, step: int = -1) -> Dict[str, np.ndarray]:
        """The disks at written step ``step``: ``positions`` (n, 2) m, ``radii`` m,
        ``velocities`` (n, 2) m/s, ``angles`` rad, ``angular_velocities`` rad/s,
        ``links`` (m, 4) segments of contacts and bonds, ``normal_force``,
        ``tangential_force`` (N/m), ``bonded`` (1 bond, 0 contact)."""
        s = self._step(step)
        if "particles" not in s:
            raise KeyError("this model has no particles")
        return s["particles"]

    def lattice(self, step: int = -1) -> Dict[str, Any]:
        """The lattice at written step ``step``: ``vx``, ``vy`` (m/s), ``pressure`` (Pa),
        ``density`` (kg/m³), ``solid``, ``temperature`` (K, with heat) as arrays of shape
        (ny, nx); ``origin`` and ``spacing`` (m)."""
        s = self._step(step)
        if "lattice" not in s:
            raise KeyError("this model has no lattice")
        return s["lattice"]

    def probes_frame(self):
        """The probes as a pandas DataFrame indexed by time (needs pandas)."""
        import pandas as pd

        p = dict(self.probes)
        t = p.pop("time")
        return pd.DataFrame(p, index=pd.Index(t, name="time"))

    def to_meshio(self, step: int = -1):
        """The grid with its fields at written step ``step`` as a ``meshio.Mesh``
        (needs meshio; 2D grids and 3D tetrahedra)."""
        import meshio

        g = self.grid
        if g is None:
            raise ValueError("this model has no grid")
        names = {5: "triangle", 9: "quad", 10: "tetra"}
        if any(int(t) not in names for t in np.unique(g.cell_types)):
            raise ValueError("meshio conversion needs triangles, quads or tetrahedra")
        cells = g.cells()
        blocks, order = [], []
        for t in np.unique(g.cell_types):
            idx = np.flatnonzero(g.cell_types == t)
            blocks.append((names[int(t)], np.array([cells[i] for i in idx])))
            order.append(idx)
        s = self._step(step)
        cell_data = {k: [v[i] for i in order] for k, v in s["cell"].items()}
        return meshio.Mesh(g.points, blocks, point_data=dict(s["point"]), cell_data=cell_data)

    def to_pyvista(self, step: int = -1):
        """The grid with its fields at written step ``step`` as a
        ``pyvista.UnstructuredGrid`` (needs pyvista)."""
        import pyvista as pv

        g = self.grid
        if g is None:
            raise ValueError("this model has no grid")
        cells = []
        for c in g.cells():
            cells.append(len(c))
            cells.extend(c)
        ug = pv.UnstructuredGrid(np.array(cells), g.cell_types, g.points)
        s = self._step(step)
        for k, v in s["point"].items():
            ug.point_data[k] = v
        for k, v in s["cell"].items():
            ug.cell_data[k] = v
        return ug

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"Result({s.get('scene', '?')!r}, status={s.get('status', 'failed')!r}, "
            f"{len(self.times)} written steps)"
        )


# The lower-level modules (grids without a scene, local cell-law matrices); imported last
# because `grid` builds the `Grid` defined above.
from . import grid, laws  # noqa: E402
