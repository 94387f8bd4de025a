"""The examples of examples/python run (reduced: --small) and give sane numbers."""

import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


def run(name, tmp_path):
    p = subprocess.run(
        [sys.executable, str(EXAMPLES / name), "--small", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_mandel_matches_its_closed_form(tmp_path):
    out = run("mandel.py", tmp_path)
    worst = float(out.split("largest error ")[1].split(" %")[0])
    assert worst < 5.0, out
    pytest.importorskip("matplotlib")
    assert (tmp_path / "mandel.png").stat().st_size > 0


def test_the_hydrofrac_sweep_runs_in_processes(tmp_path):
    out = run("hydrofrac_sweep.py", tmp_path)
    rows = [l.split() for l in out.splitlines()[1:] if l.strip()]
    assert len(rows) == 2
    # The initial pore pressure is 10 MPa; the well pressure rises above it.
    assert all(float(r[1]) > 10.0 for r in rows), out
    pytest.importorskip("matplotlib")
    assert (tmp_path / "breakdown.png").stat().st_size > 0


def test_the_lbm_drag_study_runs(tmp_path):
    out = run("lbm_drag.py", tmp_path)
    cd = float(out.split("c_D = ")[1].split()[0])
    # Two seconds in, with the inflow just ramped up: the drag is positive and of the
    # benchmark's order.
    assert 0.5 < cd < 20, out
